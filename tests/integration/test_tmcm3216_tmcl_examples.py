#!/usr/bin/python3
"""PyTrinamic's TMCM-3216 TMCL examples (examples/modules/TMCM3216/TMCL/: rotate_demo.py,
stop_switch_demo.py, eight_point_ramp_demo.py, PyTrinamic 84382a8) replayed over TCP against
`motwin serve --module tmcm-3216 --firmware tmcl` (docs/tmcm-3216-tmcl.md), as their
`socket_serial_tmcl` interface sends them: raw 9-byte frames to module 1, motor 0, one request at
a time. `motor.max_acceleration = 20000` in two of them sends nothing (PyTrinamic's motor class
has no such property). Where a script sleeps, the replay waits the same simulated time (GP 132);
its loops without a timeout get a bound. Each test asserts the outcome its script waits for.
"""

import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from motwin_harness import (  # noqa: E402
    BANK_GLOBAL, MST, MVP, MVP_ABS, ROR, STATUS_OK, Server, TempDir, TestFailure, check, check_equal, expect_reply,
    run_tests,
)

MVP_REL = 1
TARGET_POSITION, ACTUAL_POSITION, ACTUAL_VELOCITY, MAX_VELOCITY, POSITION_REACHED, RIGHT_ENDSTOP = 0, 1, 3, 4, 8, 10
RELATIVE_POSITIONING_OPTION = 127
MICROSTEPS_PER_REVOLUTION = 200 * 256  # a 200-step motor at the default resolution (AP 140 = 8)
# The scripts' loops have no timeout: the replay gives them this much simulated time.
POLL_BUDGET_MS = 30000
TICK_TIMER = 132  # GP, simulated milliseconds


class Tmcm3216TmclServer(Server):
    """`motwin serve --module tmcm-3216 --firmware tmcl` on TCP, ten times as fast as the wall clock
    (the replay waits simulated time)."""

    BANNER = r"motwin: tmcm-3216 \(3216V100\) eeprom (.+)"

    def __init__(self, motwin, state_dir, extra_args=()):
        super().__init__(motwin, state_dir, module="tmcm-3216", speed="10",
                         extra_args=["--firmware", "tmcl"] + list(extra_args))


def poll_until_reached(c, sample=None):
    """`while not motor.get_position_reached(): ...`: GAP 8 as fast as the replies come, until 1;
    `sample()` on each 0. Bounded by POLL_BUDGET_MS of simulated time (GP 132, read every 50 polls)."""
    deadline_ms = c.ggp(TICK_TIMER, BANK_GLOBAL) + POLL_BUDGET_MS
    polls = 0
    while c.gap(POSITION_REACHED) != 1:
        if sample:
            sample()
        polls += 1
        if polls % 50 == 0 and c.ggp(TICK_TIMER, BANK_GLOBAL) > deadline_ms:
            raise TestFailure(f"AP 8 still 0 after {POLL_BUDGET_MS} ms (simulated); AP 0 = {c.gap(TARGET_POSITION)}, "
                              f"AP 1 = {c.gap(ACTUAL_POSITION)}, AP 3 = {c.gap(ACTUAL_VELOCITY)}")


def test_rotate_demo(motwin):
    """rotate_demo.py: ROR 50000, 5 s, MST, GAP 1 (print), 5 s, move_by(actual position, 50000)
    (GAP 1, SAP 4 50000, MVP REL by it), loop on AP 8, 5 s, move_to(0, 100000) (SAP 4 100000, MVP
    ABS 0), loop on AP 8. The axis ends at 0. At AP 127's default the relative move adds to the last
    target (0: nothing moved by position before), as Trinamic's TMCL firmwares do, so it ends where
    the axis stands; the script's "Doubling moved distance" needs AP 127 = 1, which the replay then
    sets and checks too (docs/tmcm-3216-tmcl.md "Decisions")."""
    with TempDir() as tmp, Tmcm3216TmclServer(motwin, os.path.join(tmp, "state")) as server, server.tcp() as c:
        expect_reply(c.request(ROR, 0, 0, 50000), ROR, STATUS_OK, what="ROR 50000")
        c.wait_sim_ms(5000)
        check_equal(c.gap(ACTUAL_VELOCITY), 50000, "AP 3 after 5 s of ROR 50000")
        expect_reply(c.request(MST), MST, STATUS_OK, what="MST")
        c.gap(ACTUAL_POSITION)
        c.wait_sim_ms(5000)
        position = c.gap(ACTUAL_POSITION)
        # 50000 pps for about 4 s after a ramp of about a second each way (AMAX 51200).
        check(4.0 * 50000 < position < 5.5 * 50000, f"AP 1 {position} after 5 s at 50000 pps and the stop")
        c.sap(MAX_VELOCITY, 50000)
        expect_reply(c.request(MVP, MVP_REL, 0, position), MVP, STATUS_OK, what=f"MVP REL {position}")
        check_equal(c.gap(TARGET_POSITION), position, "AP 0 after MVP REL by the position read (AP 127 = 0)")
        poll_until_reached(c)
        check_equal(c.gap(ACTUAL_POSITION), position, "AP 1 when AP 8 reads 1")
        c.sap(RELATIVE_POSITIONING_OPTION, 1)
        expect_reply(c.request(MVP, MVP_REL, 0, position), MVP, STATUS_OK, what=f"MVP REL {position}, AP 127 = 1")
        check_equal(c.gap(TARGET_POSITION), 2 * position, "AP 0 after MVP REL from the actual position")
        poll_until_reached(c)
        check_equal(c.gap(ACTUAL_POSITION), 2 * position, "AP 1 when AP 8 reads 1 ('doubling moved distance')")
        c.wait_sim_ms(5000)
        c.sap(MAX_VELOCITY, 100000)
        expect_reply(c.request(MVP, MVP_ABS, 0, 0), MVP, STATUS_OK, what="MVP ABS 0")
        poll_until_reached(c)
        check_equal(c.gap(ACTUAL_POSITION), 0, "AP 1 back at 0")
        check_equal(c.gap(ACTUAL_VELOCITY), 0, "AP 3 at the end")
        server.stop()


def test_stop_switch_demo(motwin):
    """stop_switch_demo.py with a right switch two revolutions out (`--set AXIS0_REF_R_AT=2`):
    GAP 10 while 0: ROR 50000, 5 s; once 1: MST, 5 s, ROR -50000, 5 s, MST. The axis stopped at
    the switch, and left it again in the negative direction."""
    switch = ["--set", "AXIS0_REF_R_AT=2"]
    with TempDir() as tmp, Tmcm3216TmclServer(motwin, os.path.join(tmp, "state"), switch) as server, \
            server.tcp() as c:
        rounds = 0
        while c.gap(RIGHT_ENDSTOP) == 0:
            rounds += 1
            check(rounds <= 10, "AP 10 never read 1 (the right switch)")
            expect_reply(c.request(ROR, 0, 0, 50000), ROR, STATUS_OK, what="ROR 50000")
            c.wait_sim_ms(5000)
        check_equal(c.gap(ACTUAL_VELOCITY), 0, "AP 3 at the switch: the axis stopped there")
        at_switch = c.gap(ACTUAL_POSITION)
        check(abs(at_switch - 2 * MICROSTEPS_PER_REVOLUTION) < MICROSTEPS_PER_REVOLUTION // 20,
              f"AP 1 {at_switch} at the switch two revolutions out")
        expect_reply(c.request(MST), MST, STATUS_OK, what="MST")
        c.wait_sim_ms(5000)
        expect_reply(c.request(ROR, 0, 0, -50000), ROR, STATUS_OK, what="ROR -50000")
        c.wait_sim_ms(5000)
        expect_reply(c.request(MST), MST, STATUS_OK, what="MST")
        left = c.gap(ACTUAL_POSITION)
        check(left < at_switch - 4 * 50000, f"AP 1 {left} after 5 s of ROR -50000 from {at_switch}")
        check_equal(c.gap(RIGHT_ENDSTOP), 0, "AP 10 once the axis left the switch")
        server.stop()


def test_eight_point_ramp_demo(motwin):
    """eight_point_ramp_demo.py: its SAPs (A1 and V1 written twice, A2 and V2 left at 0), SAP 1 0,
    MVP ABS 100000, then GAP 8 and while 0 GAP 1 and GAP 3 (its samples), MVP ABS 0 and the same.
    The first poll after each MVP reads 0 (else samples[0] raises IndexError), both targets are
    reached, and the samples show VSTART, the A1 segment and the AMAX segment up to about VMAX."""
    settings = ((4, 40000), (5, 30000), (15, 5000), (16, 10000), (15, 15000), (16, 20000), (17, 20000),
                (36, 10000), (18, 5000), (19, 5000), (20, 5000), (21, 31250))
    with TempDir() as tmp, Tmcm3216TmclServer(motwin, os.path.join(tmp, "state")) as server, server.tcp() as c:
        for number, value in settings:
            c.sap(number, value)
        c.sap(ACTUAL_POSITION, 0)
        for target in (100000, 0):
            expect_reply(c.request(MVP, MVP_ABS, 0, target), MVP, STATUS_OK, what=f"MVP ABS {target}")
            samples = []
            poll_until_reached(c, lambda: samples.append((c.gap(ACTUAL_POSITION), c.gap(ACTUAL_VELOCITY))))
            check(samples, f"MVP {target}: AP 8 read 1 at the first poll (the script's samples[0] fails)")
            check_equal(c.gap(ACTUAL_POSITION), target, f"AP 1 after the move to {target}")
            speeds = [abs(v) for _, v in samples]
            moving = [v for v in speeds if v > 0]
            check(moving and moving[0] >= 5000, f"MVP {target}: the first speed {moving[:1]} below VSTART 5000")
            check(39000 < max(speeds) <= 40000, f"MVP {target}: top speed {max(speeds)}, VMAX 40000")
            # Below V1 (20000) the axis accelerates with A1 (15000), above it with AMAX (30000):
            # the speeds seen cover both segments.
            check(any(5000 < v < 20000 for v in speeds) and any(20000 < v < 40000 for v in speeds),
                  f"MVP {target}: speeds {speeds[::max(1, len(speeds) // 20)]}")
        server.stop()


def test_tmcl_over_can_beside_a_canopen_tmcm3216(motwin):
    """`--node tmcm-3216:firmware=tmcl` beside a CANopen TMCM-3216 on one bus: the TMCL node
    answers TMCL over CAN (GP 71 = 1 / GP 70 = 2) in the 7- and 8-byte forms, motors 0..2, status
    4 for motor 3; an MVP on motor 2 moves only that axis; the CANopen node boots after an NMT
    reset on the same bus."""
    from can_bus_harness import BusServer, TmclCan, open_bus, receive

    with TempDir() as tmp, BusServer(motwin, os.path.join(tmp, "state"),
                                     ["--node", "tmcm-3216:firmware=tmcl", "--node", "tmcm-3216:node-id=5",
                                      "--can", "socketcand:127.0.0.1:0", "--speed", "10"]) as server:
        check_equal([banner[2] for banner in server.banners], ["3216V100", "CANopen V1.04"], "the two firmwares")
        bus = open_bus(server.port())
        try:
            tmcl = TmclCan(bus)
            tmcl.send_raw([0x81, 5], can_id=0)  # NMT reset node 5: the CANopen node boots again
            receive(bus, lambda m: m.arbitration_id == 0x705 and bytes(m.data) == b"\x00", 10.0,
                    "the CANopen node's boot-up")
            check_equal(tmcl.ok(136, 1), (3216 << 16) | (1 << 8), "command 136 type 1 over CAN")
            check_equal(tmcl.request(6, 1, 3)[1], 4, "GAP on motor 3: status 4")
            tmcl.ok(5, 4, 2, 100000, length=8)
            check_equal(tmcl.ok(6, 4, 2), 100000, "AP 4 of motor 2")
            check_equal(tmcl.ok(6, 4, 1), 51200, "AP 4 of motor 1 untouched")
            tmcl.ok(4, 0, 2, 51200)  # MVP ABS one revolution on motor 2
            deadline_ms = tmcl.ok(10, TICK_TIMER, 0) + POLL_BUDGET_MS  # GP 132: simulated time
            while tmcl.ok(6, 8, 2) != 1:
                check(tmcl.ok(10, TICK_TIMER, 0) < deadline_ms, f"motor 2 at {tmcl.ok(6, 1, 2)} after {POLL_BUDGET_MS} ms")
            check_equal(tmcl.ok(6, 1, 2), 51200, "AP 1 of motor 2")
            check_equal([tmcl.ok(6, 1, motor) for motor in (0, 1)], [0, 0], "AP 1 of motors 0 and 1")
        finally:
            bus.shutdown()
        server.stop()


if __name__ == "__main__":
    run_tests([test_rotate_demo, test_stop_switch_demo, test_eight_point_ramp_demo,
               test_tmcl_over_can_beside_a_canopen_tmcm3216])
