#!/usr/bin/python3
"""A firmware change on one state directory of the TMCM-3216 (docs/tmcm-3216-tmcl.md "Changing
firmware"): 6081 of axis 1 written by SDO and stored (1010) under the CANopen firmware reads back
as AP 4 of motor 1 under `--firmware tmcl` on the same directory, and AP 4 of motor 1 stored by
STAP under the TMCL firmware reads back as 6881 under the CANopen firmware. Each change says so in
one stderr line and sets nothing aside as damaged.
"""

import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import SAVE, CanServer, check, check_equal, run_can_tests  # noqa: E402
from motwin_harness import Server, TempDir  # noqa: E402

NODE = 7
MAX_VELOCITY = 4  # AP 4 <-> 6081 (+ 0x800 per axis)
PROFILE_VELOCITY_AXIS1 = 0x6081 + 0x800
SAVE_MOTOR1 = 5  # 1010 sub 4 + n
TO_TMCL = "was written by firmware CANopen V1.04; 3216V100 takes it over like a firmware update"
TO_CANOPEN = "was written by firmware 3216V100; CANopen V1.04 takes it over like a firmware update"


class TmclServer(Server):
    """`motwin serve --module tmcm-3216 --firmware tmcl` on TCP."""

    BANNER = r"motwin: tmcm-3216 \(3216V100\) eeprom (.+)"

    def __init__(self, motwin, state_dir):
        super().__init__(motwin, state_dir, module="tmcm-3216", extra_args=["--firmware", "tmcl"])


def check_one_change_line(server, text):
    lines = server.stderr_lines()
    check_equal(sum(text in line for line in lines), 1, f"stderr lines saying '{text}': {lines!r}")
    check(not any("damaged" in line for line in lines), f"no damaged image reported: {lines!r}")


def check_nothing_set_aside(state_dir):
    left = sorted(name for name in os.listdir(state_dir) if name.endswith(".damaged"))
    check_equal(left, [], "files set aside as damaged")


def store_under_tmcl(motwin, state, max_velocity):
    """AP 4 of motor 1 set and stored (STAP) under the TMCL firmware, on a fresh image."""
    with TmclServer(motwin, state) as server, server.tcp() as c:
        c.sap(MAX_VELOCITY, max_velocity, motor=1)
        c.stap(MAX_VELOCITY, motor=1)
        server.stop()
        check(not any("takes it over" in line for line in server.stderr_lines()), "a fresh image: no change")


def check_canopen_took_over(motwin, state, max_velocity, what, more=lambda bus: None):
    """6881 under the CANopen firmware is `max_velocity`; one change line; nothing set aside."""
    with CanServer(motwin, state, node_id=NODE) as server, server.bus() as bus:
        check_equal(bus.upload_u(NODE, PROFILE_VELOCITY_AXIS1, 0), max_velocity, what)
        more(bus)
        server.stop()
        check_one_change_line(server, TO_CANOPEN)
    check_nothing_set_aside(state)


def test_canopen_setting_read_by_the_tmcl_firmware_and_back(motwin):
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        with CanServer(motwin, state, node_id=NODE) as server, server.bus() as bus:
            bus.download(NODE, PROFILE_VELOCITY_AXIS1, 0, 23456, 4)
            bus.download(NODE, 0x1010, SAVE_MOTOR1, SAVE, 4)
            server.stop()
        with TmclServer(motwin, state) as server, server.tcp() as c:
            check_equal(c.gap(MAX_VELOCITY, motor=1), 23456, "AP 4 of motor 1 after the change to TMCL")
            check_equal(c.gap(MAX_VELOCITY, motor=0), 51200, "AP 4 of motor 0: the default")
            c.sap(MAX_VELOCITY, 34567, motor=1)
            c.stap(MAX_VELOCITY, motor=1)
            server.stop()
            check_one_change_line(server, TO_TMCL)
        check_nothing_set_aside(state)
        check_canopen_took_over(motwin, state, 34567, "6881 after the change back")


def test_tmcl_setting_read_by_the_canopen_firmware(motwin):
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        store_under_tmcl(motwin, state, 45678)
        check_canopen_took_over(motwin, state, 45678, "6881 after the change to CANopen",
                                lambda bus: check_equal(bus.upload_u(NODE, 0x6081, 0), 51200, "6081 of axis 0: the default"))


def test_a_change_killed_while_writing_is_done_again_at_the_next_start(motwin):
    """The converted image is written atomically: a SIGKILL just before its rename (the crash-point
    hook, docs/host-runtime.md) leaves the TMCL firmware's image, which the next start converts."""
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        store_under_tmcl(motwin, state, 56789)
        crashing = CanServer(motwin, state, node_id=NODE, env={"MOTWIN_CRASH_AT_PERSIST_STEP": "rename"})
        try:
            check_equal(crashing.start_expect_failure(), -9, "serve killed before the rename")
        finally:
            crashing.cleanup()
        check_canopen_took_over(motwin, state, 56789, "6881 after the change, done again")
        check(not os.path.exists(os.path.join(state, "tmcm-3216.eeprom.tmp")), "the temporary file is gone")


if __name__ == "__main__":
    run_can_tests([test_canopen_setting_read_by_the_tmcl_firmware_and_back, test_tmcl_setting_read_by_the_canopen_firmware,
                   test_a_change_killed_while_writing_is_done_again_at_the_next_start])
