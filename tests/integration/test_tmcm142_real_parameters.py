#!/usr/bin/python3
"""The TMCM-142 numbered like the real module.

- `motwin params --module tmcm-142` lists every axis and global parameter of the real module's
  list (tests/data/tmcm142_real_parameters.csv, with its source in its header) at its number and
  under its name (compared without case, spaces and punctuation: "MaxVelocity" = "max velocity").
- An EEPROM image that Motwin wrote with the numbering before (NVM layout 1, the file
  tests/data/tmcm142_nvm_layout1.eeprom, made as tests/data/README.md says) is migrated by
  `motwin serve`: one stderr line, nothing called damaged, every setting at its new number.
"""

import csv
import io
import os
import re
import shutil
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from motwin_harness import (  # noqa: E402
    TempDir, Tmcm142Server, check, check_equal, damaged_lines, read_eeprom_image, run_tests)

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data")
REAL_LIST = os.path.join(DATA, "tmcm142_real_parameters.csv")
LAYOUT1_IMAGE = os.path.join(DATA, "tmcm142_nvm_layout1.eeprom")
BANK_USER = 2
IMAGE_ADDRESS = 3  # SGP 66, 0, 3 when the image was made
GAP, GGP = 6, 10


def read(c, command, number, bank, what):
    reply = c.request(command, number, bank, address=IMAGE_ADDRESS)
    check_equal(reply.status, 100, f"{what}: status ({reply.raw.hex(' ')})")
    return reply.value


def name_key(name):
    return re.sub(r"[^a-z0-9]", "", name.lower())


def real_list():
    with open(REAL_LIST, encoding="utf-8") as f:
        rows = [line for line in f if not line.startswith("#")]
    return [(row["kind"], int(row["number"]), row["name"]) for row in csv.DictReader(io.StringIO("".join(rows)))]


def test_params_lists_every_real_parameter_under_its_real_name(motwin):
    result = subprocess.run([motwin, "params", "--module", "tmcm-142", "--format", "csv"], capture_output=True,
                            text=True, timeout=60, stdin=subprocess.DEVNULL)
    check_equal(result.returncode, 0, f"motwin params exit status (stderr {result.stderr!r})")
    listed = {}
    for row in csv.DictReader(io.StringIO(result.stdout)):
        if row["kind"] == "axis" or (row["kind"] == "global" and row["bank"] == "0"):
            listed[(row["kind"], int(row["number"]))] = row["name"]
    expected = real_list()
    check_equal(sum(1 for kind, _, _ in expected if kind == "axis"), 62, "axis parameters in the real list")
    check_equal(sum(1 for kind, _, _ in expected if kind == "global"), 22, "global parameters in the real list")
    missing = [(kind, number, name) for kind, number, name in expected if (kind, number) not in listed]
    check(not missing, f"real parameters motwin params does not list: {missing}")
    renamed = [(kind, number, name, listed[(kind, number)]) for kind, number, name in expected
               if name_key(listed[(kind, number)]) != name_key(name)]
    check(not renamed, f"listed under another name (kind, number, real, Motwin): {renamed}")
    # Numbers outside the real list are Motwin's own and must say so (GP 64 and 73, from the TMCM-351).
    real_numbers = {(kind, number) for kind, number, _ in expected}
    extra = sorted(key for key in listed if key not in real_numbers)
    check_equal(extra, [("global", 64), ("global", 73)], "parameters the real list does not have")


def test_a_layout_1_image_is_migrated_at_start(motwin):
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        os.makedirs(state)
        shutil.copyfile(LAYOUT1_IMAGE, os.path.join(state, "tmcm-142.eeprom"))
        with Tmcm142Server(motwin, state) as server:
            with server.tcp() as c:
                def gap(number):
                    return read(c, GAP, number, 0, f"GAP {number}")
                check_equal(gap(4), 1000000, "AP 4")
                check_equal(gap(5), 20000, "AP 5")
                check_equal(gap(16), 20000, "AP 16 (= AP 5)")
                check_equal(gap(17), 0, "AP 17 (deceleration as AP 5)")
                check_equal(gap(18), 500, "AP 18 (the gentlest of the four bows)")
                check_equal(gap(19), 0, "AP 19 shaft")
                check_equal(gap(20), 50, "AP 20 standby delay (was AP 214)")
                check_equal(gap(43), 1, "AP 43 encoder mode (bit 0 was AP 46)")
                check_equal(gap(212), 100, "AP 212")
                check_equal(read(c, GGP, 5, BANK_USER, "GGP 5, 2"), 12345, "user variable 5")
            server.stop()
            lines = server.stderr_lines()
        check(not damaged_lines(lines), f"nothing is damaged: {lines!r}")
        migrated = [line for line in lines if "migrated to layout 2" in line]
        check_equal(len(migrated), 1, f"one migration line in {lines!r}")
        check(not os.path.exists(os.path.join(state, "tmcm-142.eeprom.damaged")), "no .damaged file")
        check_equal(read_eeprom_image(os.path.join(state, "tmcm-142.eeprom")).layout_version, 2,
                    "the file is layout 2 now")


if __name__ == "__main__":
    run_tests([test_params_lists_every_real_parameter_under_its_real_name, test_a_layout_1_image_is_migrated_at_start])
