#!/usr/bin/python3
"""The TMCM-3216 manual's CiA-402 examples step by step over the socketcand server, raw frames on
Debian's python3-can: 6.2 (profile position to 500000), 7.2 (profile velocity at 100000) and 8.3
(homing with method 19 on a home switch at one motor revolution). The simulated time runs faster
than the wall clock (--speed) so that the moves take seconds of wall time.
"""

import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import (NMT_RESET_NODE, STATE_BOOTUP, CanServer, check,  # noqa: E402
                             check_equal, run_can_tests)
from motwin_harness import TempDir  # noqa: E402

NODE = 3
# Simulated seconds per wall second. A state read right after the command that starts a move
# must come before the move ends: at 10 the 10.8 s move of 6.2 leaves 1 s of wall time for it; the
# homing of 8.3 (about a second of simulated time) runs in real time.
SPEED = "10"
REALTIME = "1"
USTEPS_PER_REV = 256 * 200


def serve(motwin, tmp, *extra, speed=SPEED):
    return CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE, speed=speed, extra_args=extra)


def reset(bus):
    """'Assume that the module is reset by NMT commands before': reset node, wait for the boot-up."""
    bus.nmt(NMT_RESET_NODE, NODE)
    bus.wait_state(NODE, STATE_BOOTUP)


def wait_status(bus, mask, value, sim_timeout, offset=0):
    """Polls 6041 until (6041 & mask) == value, within `sim_timeout` seconds of simulated time
    (the host may fall behind the wall clock); returns the statusword."""
    return bus.poll_sim(NODE, lambda: bus.upload_u(NODE, 0x6041 + offset, 0), lambda status: status & mask == value,
                        sim_timeout, f"6041: {value:#06x} under mask {mask:#06x}", interval=0.01)


def i32(value):
    return value - (1 << 32) if value & 0x80000000 else value


def test_manual_6_2_profile_position(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        reset(bus)
        bus.download(NODE, 0x2005, 0, 3, 4)        # no limit switches connected
        bus.download(NODE, 0x6060, 0, 1, 1)        # pp
        check_equal(bus.upload_u(NODE, 0x6061, 0), 1, "6061 follows 6060")
        bus.download(NODE, 0x6040, 0, 6, 2)
        check_equal(bus.upload_u(NODE, 0x6041, 0) & 0x6F, 0x21, "READY_TO_SWITCH_ON")
        bus.download(NODE, 0x6040, 0, 7, 2)
        check_equal(bus.upload_u(NODE, 0x6041, 0) & 0x6F, 0x23, "SWITCHED_ON")
        bus.download(NODE, 0x6040, 0, 15, 2)
        check_equal(bus.upload_u(NODE, 0x6041, 0) & 0x6F, 0x27, "OPERATION_ENABLED")
        bus.download(NODE, 0x607A, 0, 500000, 4)
        bus.download(NODE, 0x6040, 0, 31, 2)       # new set-point: the motor starts
        status = bus.upload_u(NODE, 0x6041, 0)
        check(status & 0x1000, f"set-point acknowledged (bit 12): {status:#06x}")
        bus.download(NODE, 0x6040, 0, 15, 2)       # reset the activation while moving
        # The motor starts at the next tick, which a loaded host may run after these requests.
        status = bus.poll_sim(NODE, lambda: bus.upload_u(NODE, 0x6041, 0), lambda value: value & 0x4000, 1.0,
                              "motor activity (bit 14)", fail=False) or bus.upload_u(NODE, 0x6041, 0)
        check_equal(status & 0x1400, 0, "bit 12 cleared, target not reached yet")
        check(status & 0x4000, f"motor activity (bit 14): {status:#06x}")
        # 51200 pps, 51200 pps²: about 10.8 s of simulated time.
        wait_status(bus, 0x0400, 0x0400, 30.0)  # 1.1 s of wall time when the host keeps up
        check_equal(i32(bus.upload_u(NODE, 0x6064, 0)), 500000, "6064 at the target")
        check_equal(i32(bus.upload_u(NODE, 0x6062, 0)), 500000, "6062 at the target")
        check_equal(bus.upload_u(NODE, 0x606C, 0), 0, "606C standing")
        server.stop()


def test_manual_7_2_profile_velocity(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        reset(bus)
        bus.download(NODE, 0x2005, 0, 3, 4)
        bus.download(NODE, 0x6060, 0, 3, 1)        # pv
        for cw in (6, 7, 15):
            bus.download(NODE, 0x6040, 0, cw, 2)
        check_equal(bus.upload_u(NODE, 0x6041, 0) & 0x6F, 0x27, "OPERATION_ENABLED")
        bus.download(NODE, 0x60FF, 0, 100000, 4)   # the motor accelerates to that speed
        wait_status(bus, 0x0400, 0x0400, 20.0)     # ~2 s simulated at 51200 pps²
        check_equal(bus.upload_u(NODE, 0x606C, 0), 100000, "606C at the target velocity")
        p1 = i32(bus.upload_u(NODE, 0x6064, 0))
        bus.wait_sim(NODE, 0.1)
        p2 = i32(bus.upload_u(NODE, 0x6064, 0))
        check(p2 > p1, f"position increases at speed: {p1} -> {p2}")
        bus.download(NODE, 0x60FF, 0, 0, 4)        # stop
        wait_status(bus, 0x4400, 0x0400, 20.0)
        check_equal(bus.upload_u(NODE, 0x606C, 0), 0, "606C stopped")
        server.stop()


def test_manual_8_3_homing_method_19(motwin):
    # The home switch of motor 0 is high from one motor revolution on.
    with TempDir() as tmp, serve(motwin, tmp, "--set", "AXIS0_REF_H_AT=1.0", speed=REALTIME) as server, \
            server.bus() as bus:
        reset(bus)
        bus.download(NODE, 0x6060, 0, 6, 1)        # hm
        for cw in (6, 7, 15):
            bus.download(NODE, 0x6040, 0, cw, 2)
        bus.download(NODE, 0x6098, 0, 19, 1)
        bus.download(NODE, 0x6099, 1, 50000, 4)
        bus.download(NODE, 0x6099, 2, 10000, 4)
        status = bus.upload_u(NODE, 0x6041, 0)
        check_equal(status & 0x3400, 0x0400, "idle in hm: bit 10 set, bits 12/13 clear")
        bus.download(NODE, 0x6040, 0, 31, 2)       # start homing
        status = bus.upload_u(NODE, 0x6041, 0)
        check_equal(status & 0x3400, 0, "homing: bit 10 dropped with the bit 4 edge")
        status = wait_status(bus, 0x3400, 0x1400, 40.0)
        check_equal(i32(bus.upload_u(NODE, 0x6064, 0)), 0, "6064 = home offset 0 at the home switch edge")
        bus.download(NODE, 0x6040, 0, 15, 2)
        # Back in pp the home position is the origin: a move to one revolution forward.
        bus.download(NODE, 0x6060, 0, 1, 1)
        bus.download(NODE, 0x607A, 0, USTEPS_PER_REV, 4)
        bus.download(NODE, 0x6040, 0, 31, 2)
        bus.download(NODE, 0x6040, 0, 15, 2)
        wait_status(bus, 0x0400, 0x0400, 10.0)
        check_equal(i32(bus.upload_u(NODE, 0x6064, 0)), USTEPS_PER_REV, "moved from the new origin")
        server.stop()


def main():
    run_can_tests([
        test_manual_6_2_profile_position,
        test_manual_7_2_profile_velocity,
        test_manual_8_3_homing_method_19,
    ])


if __name__ == "__main__":
    main()
