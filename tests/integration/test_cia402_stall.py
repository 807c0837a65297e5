#!/usr/bin/python3
"""Stop on stall over the socketcand server with the physical NEMA17 model (--motor nema17): an
obstacle blocks axis 0 at a scenario time (AXIS0_BLOCKED), StallGuard2's load value 2101 falls to
0, the stop on stall (20A4 above 10000 pps) acts, EMCY 3230 names motor 0, and the axis goes to
FAULT (20A7 = 0) or just stops and stays in operation enabled (20A7 = 1).
"""

import os
import struct
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import NMT_START, CanServer, check, check_equal, run_can_tests  # noqa: E402
from motwin_harness import TempDir  # noqa: E402

NODE = 6
# Simulated seconds after start (6 s of wall time at --speed 2): the set-up (python-can's start,
# the SDO writes, the acceleration) must end before, also on a loaded machine.
BLOCK_AT_S = 12.0


def stall_run(motwin, tmp, option):
    scenario = os.path.join(tmp, "scenario.txt")
    with open(scenario, "w") as f:
        f.write(f"{BLOCK_AT_S} AXIS0_BLOCKED 1\n")
    server = CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE, speed="2",
                       extra_args=["--motor", "nema17", "--scenario", scenario])
    with server, server.bus() as bus:
        bus.nmt(NMT_START, NODE)
        bus.download(NODE, 0x2005, 0, 3, 4)         # no limit switches
        bus.download(NODE, 0x20A4, 0, 10000, 4)     # stop on stall above 10000 pps
        bus.download(NODE, 0x20A7, 0, option, 1)
        bus.download(NODE, 0x6060, 0, 3, 1)
        for cw in (6, 7, 15):
            bus.download(NODE, 0x6040, 0, cw, 2)
        bus.download(NODE, 0x60FF, 0, 40000, 4)
        # At speed after 0.8 s of simulated time, well before the obstacle.
        bus.poll_sim(NODE, lambda: bus.upload_u(NODE, 0x606C, 0), lambda velocity: velocity == 40000, 5.0,
                     "606C at 40000", interval=0.05)
        bus.wait_sim(NODE, 0.4)
        free_load = bus.upload_u(NODE, 0x2101, 0)
        check(bus.sim_now(NODE) < BLOCK_AT_S, "606C did not reach 40000 before the obstacle")
        check(free_load > 200, f"2101 high while running freely: {free_load}")
        emcy = bus.receive_sim(NODE, lambda m: m.arbitration_id == 0x80 + NODE, BLOCK_AT_S + 12.0, "EMCY 3230")
        data = bytes(emcy.data)
        check_equal(struct.unpack_from("<H", data, 0)[0], 0x3230, "EMCY code: StallGuard2 error")
        check_equal(data[4], 0, "additional byte 2: motor 0")
        check_equal(bus.upload_u(NODE, 0x2101, 0), 0, "2101 at the stall")
        bus.wait_sim(NODE, 1.2)
        status = bus.upload_u(NODE, 0x6041, 0)
        check_equal(bus.upload_u(NODE, 0x606C, 0), 0, "606C stopped")
        server.stop()
        return status


def test_stall_enters_fault_with_option_0(motwin):
    with TempDir() as tmp:
        status = stall_run(motwin, tmp, 0)
        check_equal(status & 0x4F, 0x08, f"FAULT after the stall (6041 = {status:#06x})")


def test_stall_only_stops_with_option_1(motwin):
    with TempDir() as tmp:
        status = stall_run(motwin, tmp, 1)
        check_equal(status & 0x6F, 0x27, f"still OPERATION ENABLED (6041 = {status:#06x})")


def main():
    run_can_tests([
        test_stall_enters_fault_with_option_0,
        test_stall_only_stops_with_option_1,
    ])


if __name__ == "__main__":
    main()
