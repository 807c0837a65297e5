#!/usr/bin/python3
"""Storage under faults: kill -9 during every kind of storage write, and a full disk.

kill -9 loops (seeded random kill times, --speed fast), each followed by a restart that must
load the image without a "damaged" report:
- program download (TMCM-1636): a client downloads program k (132, four CALC ADD k, 133) for
  k = 1, 2, ... until the kill; after the restart 134 reads one whole program j back (all four
  values equal), with j no older than the last acknowledged 133 and no newer than the last 132;
- auto-stored SGP (GP 77 is A: every SGP stores) and STGP of a user variable, alternating; the
  stored values are a prefix of the sequence and include every acknowledged store;
- CANopen 1010 store (TMCM-3216 over socketcand): 1017 = k then 1010 sub 1 "save"; after the
  restart 1017 holds a k between the last acknowledged save and the last write.
A temporary file left by the kill is gone after the restart. (Stores of SAP/STAP under kill -9
are covered by test_persistence.py.)

Full disk, without root: the server runs with RLIMIT_FSIZE one byte below the image size and
SIGXFSZ ignored, so every image write fails with EFBIG. STAP, STGP, an auto-stored SGP and the
133 of a download answer status 5; the SGP is rolled back, the downloaded program is dropped
(134 reads the old one); 1010 store answers SDO abort 06060000. The image file is byte for byte
what it was, the server keeps serving and exits cleanly, and a restart without the limit loads
the old values.
"""

import os
import random
import struct
import sys
import threading
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import SAVE, CanServer, RawSocketcand  # noqa: E402
from motwin_harness import (  # noqa: E402
    BANK_GLOBAL, BANK_USER, SGP, STAP, STATUS_OK, STGP, Server, TempDir, TestFailure,
    check, check_equal, damaged_lines, expect_reply, frame, parse_reply, read_eeprom_image, run_tests,
)

STATUS_EEPROM = 5
CALC, STOP_PROGRAM, DOWNLOAD_START, DOWNLOAD_END, READ_MEMORY = 19, 128, 132, 133, 134
PROGRAM_LENGTH = 4
NODE = 5
ABORT_HARDWARE = 0x06060000
KILL_ITERATIONS = 25


# --- Helpers ------------------------------------------------------------------------------------

def limited_file_size_args(args, limit_bytes):
    """The server command wrapped so that it runs with RLIMIT_FSIZE and SIGXFSZ ignored (both
    survive exec), the way `ulimit -f` in a shell with `trap '' XFSZ` would start it."""
    launcher = ("import os, resource, signal, sys\n"
                "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
                f"resource.setrlimit(resource.RLIMIT_FSIZE, ({limit_bytes}, {limit_bytes}))\n"
                "os.execv(sys.argv[1], sys.argv[1:])\n")
    return [sys.executable, "-c", launcher] + list(args)


def read_bytes(path):
    with open(path, "rb") as f:
        return f.read()


def leftovers(state_dir):
    return sorted(name for name in os.listdir(state_dir) if name.endswith(".tmp"))


def check_clean_restart(server, state_dir, when):
    lines = damaged_lines(server.stderr_lines())
    check(not lines, f"{when}: 'damaged' report after the restart: {lines!r}")
    check_equal(leftovers(state_dir), [], f"{when}: temporary files after the restart")


class Killer(threading.Thread):
    """SIGKILLs the server `delay` seconds after start()."""

    def __init__(self, server, delay):
        super().__init__(daemon=True)
        self.server = server
        self.delay = delay

    def run(self):
        time.sleep(self.delay)
        try:
            self.server.proc.kill()
        except OSError:
            pass


def program_request(c, command, type_=0, motor=0, value=0):
    return parse_reply(c.request_raw(frame(command, type_, motor, value)))


def download_program(c, k):
    """Program k: four CALC ADD k; returns the status of 133."""
    expect_reply(program_request(c, DOWNLOAD_START, 0, 0, 0), DOWNLOAD_START, STATUS_OK, what=f"132 of program {k}")
    for _ in range(PROGRAM_LENGTH):
        reply = program_request(c, CALC, 0, 0, k)
        check_equal(reply.status, 101, f"CALC of program {k} in download mode")
    return program_request(c, DOWNLOAD_END).status


def read_program_values(c):
    values = []
    for address in range(PROGRAM_LENGTH):
        reply = program_request(c, READ_MEMORY, 0, 0, address)
        check_equal((reply.status, reply.command), (STATUS_OK, CALC), f"134 at address {address}")
        values.append(reply.value)
    return values


# --- kill -9 during program download --------------------------------------------------------

def test_kill_during_program_download(motwin):
    rng = random.Random(132)
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        with Server(motwin, state, speed="fast") as server:
            with server.tcp() as c:
                check_equal(download_program(c, 0), STATUS_OK, "first download")
            server.stop()
        acked = started = k = 0
        for iteration in range(KILL_ITERATIONS):
            with Server(motwin, state, speed="fast") as server:
                check_clean_restart(server, state, f"iteration {iteration}")
                c = server.tcp()
                try:
                    values = read_program_values(c)
                    check(len(set(values)) == 1, f"iteration {iteration}: a mixed program {values}")
                    check(acked <= values[0] <= started, f"iteration {iteration}: program {values[0]} in the "
                                                        f"image, acknowledged {acked}, last started {started}")
                    acked = started = values[0]
                    killer = Killer(server, rng.uniform(0.0, 0.08))
                    killer.start()
                    try:
                        while True:
                            k += 1
                            started = k
                            if download_program(c, k) == STATUS_OK:
                                acked = k
                    except (TestFailure, OSError):
                        pass  # the kill
                    killer.join()
                finally:
                    c.close()
                server.kill()
        with Server(motwin, state, speed="fast") as server:
            check_clean_restart(server, state, "final")
            with server.tcp() as c:
                values = read_program_values(c)
                check(len(set(values)) == 1 and acked <= values[0] <= started,
                      f"final: program {values}, acknowledged {acked}, last started {started}")
            server.stop()
        print(f"  {KILL_ITERATIONS} kills, {k} downloads started, last acknowledged {acked}", flush=True)


# --- kill -9 during auto-stored SGP and STGP --------------------------------------------------

def gp77_after(step):
    """GP 77 once step `step` is stored: the factory value 1 before the first step."""
    return 1 if step == 0 else step % 2


def test_kill_during_auto_stored_sgp_and_stgp(motwin):
    """GP 77 (auto start, A: stored by every SGP) toggles 0/1; user variable 3 counts and is
    stored with STGP. Step n: SGP 77 = n % 2, then SGP/STGP uv3 = n."""
    rng = random.Random(77)
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        acked = 0
        n = 0
        for iteration in range(KILL_ITERATIONS):
            with Server(motwin, state, speed="fast") as server:
                check_clean_restart(server, state, f"iteration {iteration}")
                c = server.tcp()
                try:
                    uv3 = c.ggp(3, BANK_USER)
                    gp77 = c.ggp(77, BANK_GLOBAL)
                    # Stored n means: GP 77 of step n (n % 2) and then uv3 = n were written; a kill
                    # between the two leaves GP 77 one step ahead.
                    check(acked <= uv3 <= n, f"iteration {iteration}: uv3 {uv3}, acknowledged {acked}, last {n}")
                    check(gp77 == gp77_after(uv3) or (uv3 + 1 <= n and gp77 == gp77_after(uv3 + 1)),
                          f"iteration {iteration}: GP 77 {gp77} with uv3 {uv3} (last step {n})")
                    acked = uv3
                    n = uv3
                    Killer(server, rng.uniform(0.0, 0.06)).start()
                    try:
                        while True:
                            n += 1
                            expect_reply(c.request(SGP, 77, BANK_GLOBAL, n % 2), SGP, STATUS_OK, n % 2, "SGP 77")
                            expect_reply(c.request(SGP, 3, BANK_USER, n), SGP, STATUS_OK, n, "SGP uv3")
                            expect_reply(c.request(STGP, 3, BANK_USER), STGP, STATUS_OK, what="STGP uv3")
                            acked = n
                    except (TestFailure, OSError):
                        pass
                finally:
                    c.close()
                server.kill()
        print(f"  {KILL_ITERATIONS} kills, {n} steps, last acknowledged {acked}", flush=True)


# --- kill -9 during CANopen 1010 store --------------------------------------------------------

class RawSdo:
    """A raw socketcand connection with expedited SDO downloads and uploads to NODE."""

    def __init__(self, port):
        self.raw = RawSocketcand(port)
        check_equal(self.raw.read_element(), "< hi >", "greeting")
        self.raw.send("< open can0 >")
        check_equal(self.raw.read_element(), "< ok >", "open")
        self.raw.send("< rawmode >")
        check_equal(self.raw.read_element(), "< ok >", "rawmode")

    def request(self, data):
        self.raw.send("< send %03X 8 %s >" % (0x600 + NODE, " ".join(f"{b:02X}" for b in data)))
        while True:
            element = self.raw.read_element()
            parts = element.split()
            if len(parts) >= 5 and parts[1] == "frame" and int(parts[2], 16) == 0x580 + NODE:
                return bytes.fromhex(parts[4])

    def download(self, index, sub, value, size):
        """0 on success, else the abort code."""
        header = 0x23 | ((4 - size) << 2)
        response = self.request([header, index & 0xFF, index >> 8, sub] + list(value.to_bytes(4, "little")))
        if response[0] == 0x80:
            return struct.unpack_from("<I", response, 4)[0]
        check_equal(response[0], 0x60, f"download response for {index:04X}")
        return 0

    def upload(self, index, sub):
        response = self.request([0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0])
        check(response[0] & 0xE3 == 0x43, f"expedited upload response {response.hex()}")
        return struct.unpack_from("<I", response, 4)[0]

    def close(self):
        self.raw.close()


def can_server(motwin, state, extra_args=()):
    return CanServer(motwin, state, node_id=NODE, speed="fast", extra_args=extra_args)


def test_kill_during_canopen_1010_store(motwin):
    rng = random.Random(1010)
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        acked = 0
        k = 0
        for iteration in range(KILL_ITERATIONS):
            with can_server(motwin, state) as server:
                check_clean_restart(server, state, f"iteration {iteration}")
                sdo = RawSdo(server.can_port)
                try:
                    stored = sdo.upload(0x1017, 0)
                    check(acked <= stored <= k, f"iteration {iteration}: 1017 = {stored}, acknowledged save "
                                                f"{acked}, last written {k}")
                    acked = k = stored
                    Killer(server, rng.uniform(0.0, 0.08)).start()
                    try:
                        while True:
                            k += 1
                            check_equal(sdo.download(0x1017, 0, k, 2), 0, "1017 download")
                            check_equal(sdo.download(0x1010, 1, SAVE, 4), 0, "1010 save")
                            acked = k
                    except (TestFailure, OSError):
                        pass
                finally:
                    sdo.close()
                server.kill()
        print(f"  {KILL_ITERATIONS} kills, {k} saves started, last acknowledged {acked}", flush=True)


# --- Full disk ----------------------------------------------------------------------------------

def test_full_disk_tmcl(motwin):
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        with Server(motwin, state) as server:
            with server.tcp() as c:
                c.sap(43, 3100)
                c.stap(43)
                check_equal(download_program(c, 7), STATUS_OK, "download of program 7")
            server.stop()
        image = os.path.join(state, "tmcm-1636.eeprom")
        before = read_bytes(image)
        check(read_eeprom_image(image).problem is None, "image before the full disk")

        server = Server(motwin, state)
        server.args = limited_file_size_args(server.args, len(before) - 1)
        with server:
            with server.tcp() as c:
                check_equal(c.gap(43), 3100, "stored AP 43 loads under the limit")
                c.sap(43, 2500)
                expect_reply(c.request(STAP, 43), STAP, STATUS_EEPROM, what="STAP on a full disk")
                check_equal(c.gap(43), 2500, "RAM value of AP 43 after the failed STAP")
                c.sgp(5, BANK_USER, 42)
                expect_reply(c.request(STGP, 5, BANK_USER), STGP, STATUS_EEPROM, what="STGP on a full disk")
                expect_reply(c.request(SGP, 77, BANK_GLOBAL, 0), SGP, STATUS_EEPROM, what="auto-stored SGP 77")
                check_equal(c.ggp(77, BANK_GLOBAL), 1, "GP 77 rolled back after the failed store")
                check_equal(download_program(c, 8), STATUS_EEPROM, "133 on a full disk")
                check_equal(read_program_values(c), [7] * PROGRAM_LENGTH, "program after the failed 133")
                check_equal(read_bytes(image), before, "image file after the failed stores")
                check_equal(leftovers(state), [], "temporary files after the failed stores")
            check(any("cannot write EEPROM image" in line for line in server.stderr_lines()),
                  f"no diagnostic on stderr: {server.stderr_lines()!r}")
            server.stop()
        check_equal(read_bytes(image), before, "image file after the clean exit")

        with Server(motwin, state) as server:
            check_clean_restart(server, state, "after the full disk")
            with server.tcp() as c:
                check_equal(c.gap(43), 3100, "AP 43 after the restart")
                check_equal(c.ggp(5, BANK_USER), 0, "user variable 5 after the restart")
                check_equal(c.ggp(77, BANK_GLOBAL), 1, "GP 77 after the restart")
                check_equal(read_program_values(c), [7] * PROGRAM_LENGTH, "program after the restart")
                c.sap(43, 2600)
                c.stap(43)  # the disk has room again
            server.stop()
        check(read_bytes(image) != before, "a store after the limit is lifted writes the image")


def test_full_disk_canopen(motwin):
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        with can_server(motwin, state) as server:
            sdo = RawSdo(server.can_port)
            try:
                check_equal(sdo.download(0x1017, 0, 250, 2), 0, "1017 = 250")
                check_equal(sdo.download(0x1010, 1, SAVE, 4), 0, "1010 save")
            finally:
                sdo.close()
            server.stop()
        image = os.path.join(state, "tmcm-3216.eeprom")
        before = read_bytes(image)

        server = can_server(motwin, state)
        server.args = limited_file_size_args(server.args, len(before) - 1)
        with server:
            sdo = RawSdo(server.can_port)
            try:
                check_equal(sdo.upload(0x1017, 0), 250, "saved 1017 loads under the limit")
                check_equal(sdo.download(0x1017, 0, 400, 2), 0, "1017 = 400")
                check_equal(sdo.download(0x1010, 1, SAVE, 4), ABORT_HARDWARE, "1010 save on a full disk")
                check_equal(sdo.upload(0x1017, 0), 400, "RAM value of 1017 after the failed save")
                check_equal(read_bytes(image), before, "image file after the failed save")
                check_equal(leftovers(state), [], "temporary files after the failed save")
            finally:
                sdo.close()
            server.stop()

        with can_server(motwin, state) as server:
            check_clean_restart(server, state, "after the full disk")
            sdo = RawSdo(server.can_port)
            try:
                check_equal(sdo.upload(0x1017, 0), 250, "1017 after the restart")
            finally:
                sdo.close()
            server.stop()


if __name__ == "__main__":
    run_tests([test_full_disk_tmcl, test_full_disk_canopen, test_kill_during_program_download,
               test_kill_during_auto_stored_sgp_and_stgp, test_kill_during_canopen_1010_store])
