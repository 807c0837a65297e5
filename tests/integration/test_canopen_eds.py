#!/usr/bin/python3
"""`motwin eds` (CiA-306) against the live TMCM-3216: the file parses with configparser, lists every
object in exactly one of the object lists, each ARRAY/RECORD's SubNumber matches its sub-index
sections, [DeviceInfo] has the numeric fields python-canopen needs, and every readable default
(with $NODEID resolved) is what an SDO upload of the freshly started module returns.
"""

import configparser
import os
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import CanServer, check, check_equal  # noqa: E402
from motwin_harness import TempDir, run_tests  # noqa: E402

NODE = 9


def load_eds(motwin, tmp, *extra):
    path = os.path.join(tmp, "tmcm-3216.eds")
    result = subprocess.run([motwin, "eds", "--module", "tmcm-3216", "-o", path, *extra], capture_output=True,
                            timeout=30)
    check_equal(result.returncode, 0, f"motwin eds exit status (stderr {result.stderr!r})")
    eds = configparser.ConfigParser(interpolation=None)
    eds.optionxform = str  # keys are case-sensitive in the EDS world
    eds.read(path, encoding="ascii")
    return eds


def listed_objects(eds):
    objects = []
    for section in ("MandatoryObjects", "OptionalObjects", "ManufacturerObjects"):
        count = int(eds[section]["SupportedObjects"])
        objects += [int(eds[section][str(i)], 16) for i in range(1, count + 1)]
    return objects


def test_eds_structure(motwin):
    with TempDir() as tmp:
        eds = load_eds(motwin, tmp, "--node-id", str(NODE))
        info = eds["DeviceInfo"]
        check_equal(int(info["VendorNumber"], 0), 0x286, "VendorNumber")
        check_equal(int(info["ProductNumber"], 0), 3216, "ProductNumber")
        for key in ("NrOfRXPDO", "NrOfTXPDO", "LSS_Supported", "BaudRate_1000", "Granularity"):
            int(info[key], 0)  # present and numeric (python-canopen cannot import empty numbers)
        check_equal(eds["DeviceComissioning"]["NodeID"], str(NODE), "NodeID")
        objects = listed_objects(eds)
        check_equal(len(objects), len(set(objects)), "objects listed once")
        check(0x1000 in objects and 0x1018 in objects and 0x1A83 in objects and 0x2705 in objects,
              "expected objects listed")
        for index in objects:
            section = f"{index:04X}"
            check(eds.has_section(section), f"section [{section}]")
            if int(eds[section]["ObjectType"], 0) in (8, 9):
                subs = [s for s in eds.sections() if s.startswith(section + "sub")]
                check_equal(int(eds[section]["SubNumber"]), len(subs), f"SubNumber of {section}")
        check_equal(eds["1008"]["DefaultValue"], "TMCM-3216", "1008 default")
        check_equal(eds["1800sub1"]["DefaultValue"], "$NODEID+0x180", "1800 sub 1 default")


def test_eds_defaults_match_the_live_module(motwin):
    with TempDir() as tmp:
        eds = load_eds(motwin, tmp)
        with CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE) as server, server.bus() as bus:
            checked = 0
            for section in eds.sections():
                entry = eds[section]
                if "DataType" not in entry or entry.get("AccessType") == "wo":
                    continue
                index = int(section[:4], 16)
                sub = int(section[7:], 16) if "sub" in section else 0
                default = entry["DefaultValue"]
                if int(entry["DataType"], 0) == 0x9:
                    check_equal(bus.upload(NODE, index, sub).decode("ascii"), default, f"{section} string")
                    checked += 1
                    continue
                if default.startswith("$NODEID+"):
                    expected = NODE + int(default[len("$NODEID+"):], 0)
                else:
                    expected = int(default, 0)
                if (index, sub) in ((0x1018, 4),):
                    continue  # serial number: given by the board
                check_equal(bus.upload_u(NODE, index, sub), expected, f"{section} default")
                checked += 1
            check(checked > 200, f"only {checked} entries checked")
            server.stop()


def test_eds_refuses_modules_without_canopen(motwin):
    result = subprocess.run([motwin, "eds", "--module", "tmcm-1636"], capture_output=True, timeout=30)
    check_equal(result.returncode, 2, "exit status")
    check(b"no CANopen object dictionary" in result.stderr, f"stderr {result.stderr!r}")


if __name__ == "__main__":
    run_tests([test_eds_structure, test_eds_defaults_match_the_live_module, test_eds_refuses_modules_without_canopen])
