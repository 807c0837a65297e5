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
are covered by test_persistence.py; a kill at each step of each kind of write, made certain by
the crash hook MOTWIN_CRASH_AT_PERSIST_STEP, by test_fault_crash_points.py.)

Full disk, without root: the server runs with RLIMIT_FSIZE one byte below the image size and
SIGXFSZ ignored, so every image write fails with EFBIG.
- TMCM-1636: STAP, STGP, an auto-stored SGP and the 133 of a download answer status 5; the SGP is
  rolled back, the downloaded program is dropped (134 reads the old one).
- TMCM-142: STAP, STGP, SCO n, 255 (coordinate into the EEPROM), the auto-stored SGP 84, 133 and,
  with GP 84 = 1, an SCO that stores at once answer status 5; the SGP and the stored SCO are
  rolled back, GCO n, 255 still reads the old stored coordinate, the program is the old one.
- TMCM-3216: 1010 sub 1, 2, 4, 5, 6 (save) and 1011 sub 1, 4, 5, 6 (restore defaults) answer SDO
  abort 06060000, the RAM values stay; 1011 sub 2 ("no function") writes nothing and succeeds;
  sub 3 of both is refused (08000020). LSS store configuration answers error code 2 (storage
  media access error) and the stored node ID (2705) stays the old one.
Each time the image file is byte for byte what it was, no temporary file is left, stderr says
why, the server keeps serving and exits cleanly, and a restart without the limit loads the old
values.
"""

import os
import random
import sys
import threading
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import LOAD, SAVE, CanServer, RawSdoClient  # noqa: E402
from motwin_harness import (  # noqa: E402
    BANK_GLOBAL, BANK_USER, SGP, STAP, STATUS_OK, STGP, Server, TempDir, TestFailure, Tmcm142Server,
    check, check_equal, expect_reply, read_eeprom_image, run_tests,
)
from storage_harness import (  # noqa: E402
    ABORT_HARDWARE, PROGRAM_LENGTH, STATUS_EEPROM, check_clean_restart, download_program, on_full_disk,
    read_bytes, read_program_values, temporary_files,
)

NODE = 5
ABORT_SIGNATURE = 0x08000020  # 1010/1011 sub 3, "not used"
KILL_ITERATIONS = 25
SCO, GCO = 30, 31
COORDINATE_EEPROM_COPY = 255  # SCO/GCO n, 255: copy coordinate n to/from the EEPROM image
GP_COORDINATE_STORAGE = 84


# --- Helpers ------------------------------------------------------------------------------------

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

def can_server(motwin, state, extra_args=()):
    return CanServer(motwin, state, node_id=NODE, speed="fast", extra_args=extra_args)


def raw_sdo(server):
    return RawSdoClient(server.can_port, NODE)


def test_kill_during_canopen_1010_store(motwin):
    rng = random.Random(1010)
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        acked = 0
        k = 0
        for iteration in range(KILL_ITERATIONS):
            with can_server(motwin, state) as server:
                check_clean_restart(server, state, f"iteration {iteration}")
                sdo = raw_sdo(server)
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

def check_failed_stores_left_no_trace(server, state, image, before):
    """After the failed stores: the image file byte for byte as it was, no temporary file, and the
    reason on stderr."""
    check_equal(read_bytes(image), before, "image file after the failed stores")
    check_equal(temporary_files(state), [], "temporary files after the failed stores")
    check(any("cannot write EEPROM image" in line for line in server.stderr_lines()),
          f"no diagnostic on stderr: {server.stderr_lines()!r}")


def check_stap_stgp_and_download_refused(c, axis_parameter, stored_value, ram_value):
    """On a full disk, with program 7 stored before: the stored AP loads; STAP of `ram_value`, STGP
    of user variable 5 and the 133 of program 8 answer status 5; the RAM values stay, the program
    stays program 7."""
    check_equal(c.gap(axis_parameter), stored_value, f"stored AP {axis_parameter} loads under the limit")
    c.sap(axis_parameter, ram_value)
    expect_reply(c.request(STAP, axis_parameter), STAP, STATUS_EEPROM, what=f"STAP {axis_parameter} on a full disk")
    check_equal(c.gap(axis_parameter), ram_value, f"RAM value of AP {axis_parameter} after the failed STAP")
    c.sgp(5, BANK_USER, 42)
    expect_reply(c.request(STGP, 5, BANK_USER), STGP, STATUS_EEPROM, what="STGP on a full disk")
    check_equal(c.ggp(5, BANK_USER), 42, "RAM value of user variable 5 after the failed STGP")
    check_equal(download_program(c, 8), STATUS_EEPROM, "133 on a full disk")
    check_equal(read_program_values(c), [7] * PROGRAM_LENGTH, "program after the failed 133")


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

        with on_full_disk(Server(motwin, state), before) as server:
            with server.tcp() as c:
                check_stap_stgp_and_download_refused(c, 43, 3100, 2500)
                expect_reply(c.request(SGP, 77, BANK_GLOBAL, 0), SGP, STATUS_EEPROM, what="auto-stored SGP 77")
                check_equal(c.ggp(77, BANK_GLOBAL), 1, "GP 77 rolled back after the failed store")
                check_failed_stores_left_no_trace(server, state, image, before)
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


def coordinate(c, number, motor=0):
    return expect_reply(c.request(GCO, number, motor), GCO, STATUS_OK, what=f"GCO {number}, {motor}").value


def test_full_disk_tmcm142(motwin):
    """STAP (AP 20), STGP, SCO n, 255 (copy to the EEPROM), the auto-stored SGP 84, 133 and, with
    GP 84 = 1, an SCO that stores at once: status 5, RAM as the manual's rollback says, the image
    byte for byte as it was; a restart without the limit loads the old values."""
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        with Tmcm142Server(motwin, state) as server:
            with server.tcp() as c:
                c.sap(20, 300)
                c.stap(20)
                c.sgp(5, BANK_USER, 11)
                c.stgp(5, BANK_USER)
                c.ok(SCO, 3, 0, 1000, what="SCO 3, 0, 1000")
                c.ok(SCO, 3, COORDINATE_EEPROM_COPY, 0, what="SCO 3, 255: coordinate 3 into the EEPROM")
                check_equal(download_program(c, 7), STATUS_OK, "download of program 7")
            server.stop()
        image = os.path.join(state, "tmcm-142.eeprom")
        before = read_bytes(image)

        # GP 84 = 0: coordinates live in RAM, SCO n, 255 copies one into the EEPROM.
        with on_full_disk(Tmcm142Server(motwin, state), before) as server:
            with server.tcp() as c:
                check_stap_stgp_and_download_refused(c, 20, 300, 450)
                c.ok(SCO, 3, 0, 3000, what="SCO 3, 0, 3000 (RAM)")
                expect_reply(c.request(SCO, 3, COORDINATE_EEPROM_COPY), SCO, STATUS_EEPROM,
                             what="SCO 3, 255 on a full disk")
                check_equal(coordinate(c, 3), 3000, "coordinate 3 in RAM after the failed copy")
                check_equal(coordinate(c, 3, COORDINATE_EEPROM_COPY), 1000,
                            "GCO 3, 255: the image in memory still holds the old coordinate")
                expect_reply(c.request(SGP, GP_COORDINATE_STORAGE, BANK_GLOBAL, 1), SGP, STATUS_EEPROM,
                             what="auto-stored SGP 84 on a full disk")
                check_equal(c.ggp(GP_COORDINATE_STORAGE, BANK_GLOBAL), 0, "GP 84 rolled back")
                check_failed_stores_left_no_trace(server, state, image, before)
            server.stop()

        # GP 84 = 1: every SCO of coordinates 1..20 is stored at once.
        with Tmcm142Server(motwin, state) as server:
            check_clean_restart(server, state, "after the first full disk")
            with server.tcp() as c:
                c.sgp(GP_COORDINATE_STORAGE, BANK_GLOBAL, 1)
            server.stop()
        before = read_bytes(image)
        with on_full_disk(Tmcm142Server(motwin, state), before) as server:
            with server.tcp() as c:
                check_equal(coordinate(c, 3), 1000, "stored coordinate 3 restored at power-up with GP 84 = 1")
                expect_reply(c.request(SCO, 4, 0, 2000), SCO, STATUS_EEPROM, what="stored SCO 4 on a full disk")
                check_equal(coordinate(c, 4), 0, "coordinate 4 rolled back after the failed store")
                check_failed_stores_left_no_trace(server, state, image, before)
                check_equal(c.gap(20), 300, "the server still serves")
            server.stop()

        with Tmcm142Server(motwin, state) as server:
            check_clean_restart(server, state, "after the full disk")
            with server.tcp() as c:
                check_equal(c.gap(20), 300, "AP 20 after the restart")
                check_equal(c.ggp(5, BANK_USER), 11, "user variable 5 after the restart")
                check_equal((coordinate(c, 3), coordinate(c, 4)), (1000, 0), "coordinates 3, 4 after the restart")
                check_equal(read_program_values(c), [7] * PROGRAM_LENGTH, "program after the restart")
            server.stop()


def test_full_disk_canopen(motwin):
    """1010 sub 1, 2, 4..6 and 1011 sub 1, 4..6 answer 06060000 and leave the image as it was;
    1011 sub 2 ("no function") writes nothing and succeeds; sub 3 of both is refused whatever the
    disk (08000020)."""
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        with can_server(motwin, state) as server, raw_sdo(server) as sdo:
            check_equal(sdo.download(0x1017, 0, 250, 2), 0, "1017 = 250")
            for axis in range(3):
                check_equal(sdo.download(0x6081 + 0x800 * axis, 0, 5000 + axis, 4), 0, f"6081 of axis {axis}")
            check_equal(sdo.download(0x1010, 1, SAVE, 4), 0, "1010 save")
            server.stop()
        image = os.path.join(state, "tmcm-3216.eeprom")
        before = read_bytes(image)

        with on_full_disk(can_server(motwin, state), before) as server, raw_sdo(server) as sdo:
            check_equal(sdo.upload(0x1017, 0), 250, "saved 1017 loads under the limit")
            check_equal(sdo.download(0x1017, 0, 400, 2), 0, "1017 = 400")
            check_equal(sdo.download(0x1010, 1, SAVE, 4), ABORT_HARDWARE, "1010 sub 1 save on a full disk")
            check_equal(sdo.upload(0x1017, 0), 400, "RAM value of 1017 after the failed save")
            check_equal(sdo.download(0x2705, 0, 9, 1), 0, "2705 = 9")
            check_equal(sdo.download(0x1010, 2, SAVE, 4), ABORT_HARDWARE, "1010 sub 2 save on a full disk")
            for axis in range(3):
                velocity = 0x6081 + 0x800 * axis
                check_equal(sdo.download(velocity, 0, 7000 + axis, 4), 0, f"6081 of axis {axis} = {7000 + axis}")
                check_equal(sdo.download(0x1010, 4 + axis, SAVE, 4), ABORT_HARDWARE,
                            f"1010 sub {4 + axis} (motor {axis}) save on a full disk")
                check_equal(sdo.upload(velocity, 0), 7000 + axis, f"RAM value of 6081 of axis {axis}")
            for sub in (1, 4, 5, 6):
                check_equal(sdo.download(0x1011, sub, LOAD, 4), ABORT_HARDWARE, f"1011 sub {sub} on a full disk")
            check_equal(sdo.download(0x1011, 2, LOAD, 4), 0, "1011 sub 2: no function, nothing to write")
            check_equal(sdo.download(0x1010, 3, SAVE, 4), ABORT_SIGNATURE, "1010 sub 3: not used")
            check_equal(sdo.download(0x1011, 3, LOAD, 4), ABORT_SIGNATURE, "1011 sub 3: not used")
            check_failed_stores_left_no_trace(server, state, image, before)
            server.stop()

        with can_server(motwin, state) as server, raw_sdo(server) as sdo:
            check_clean_restart(server, state, "after the full disk")
            check_equal(sdo.upload(0x1017, 0), 250, "1017 after the restart")
            check_equal(sdo.upload(0x2705, 0), 1, "2705 after the restart")
            for axis in range(3):
                check_equal(sdo.upload(0x6081 + 0x800 * axis, 0), 5000 + axis, f"6081 of axis {axis} after the restart")
            server.stop()


def test_full_disk_lss_store_configuration(motwin):
    """LSS store configuration answers error code 2 ("storage media access error", CiA-305) and
    leaves the image as it was; the stored node ID stays the old one."""
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        with can_server(motwin, state) as server, raw_sdo(server) as sdo:
            sdo.lss_configure_node_id(7)
            check_equal(sdo.lss([0x17])[:2], bytes([0x17, 0]), "LSS store configuration")
            server.stop()
        image = os.path.join(state, "tmcm-3216.eeprom")
        before = read_bytes(image)

        with on_full_disk(can_server(motwin, state), before) as server, raw_sdo(server) as sdo:
            check_equal(sdo.upload(0x2705, 0), 7, "node ID stored by LSS loads under the limit")
            sdo.lss_configure_node_id(9)
            check_equal(sdo.lss([0x17])[:2], bytes([0x17, 2]), "LSS store configuration on a full disk")
            check_equal(sdo.upload(0x2705, 0), 7, "2705 after the failed store")
            check_failed_stores_left_no_trace(server, state, image, before)
            server.stop()

        with can_server(motwin, state) as server, raw_sdo(server) as sdo:
            check_clean_restart(server, state, "after the full disk")
            check_equal(sdo.upload(0x2705, 0), 7, "2705 after the restart")
            server.stop()


if __name__ == "__main__":
    run_tests([test_full_disk_tmcl, test_full_disk_tmcm142, test_full_disk_canopen,
               test_full_disk_lss_store_configuration, test_kill_during_program_download,
               test_kill_during_auto_stored_sgp_and_stgp, test_kill_during_canopen_1010_store])
