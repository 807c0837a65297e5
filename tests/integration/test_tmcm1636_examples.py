#!/usr/bin/python3
"""Trinamic's TMCM-1636 example scripts (PyTrinamic, examples/modules/TMCM1636/TMCL/) replayed
over TCP against `motwin serve --motor qbl4208-61-04-013`, the reference motor the scripts name:
the same parameter sequence the scripts send, the reads their prints make, and the outcome they
wait for. Written from what the scripts do (docs/tmcm-1636-servo.md "Presets"). Encoder velocity
mode and the script load need nothing beyond the V1.09 firmware; the others print
`drive_settings`, which reads AP 26 of the later firmware, so they run with `--firmware 1.13`.
End switches and digital inputs are driven as on a bench: switches placed on the rotor's path
(REF_R_AT, REF_L_AT), buttons pressed at a simulated time (a scenario file).
"""

import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from motwin_harness import (  # noqa: E402
    BANK_GLOBAL, MST, MVP, MVP_ABS, ROR, STATUS_OK, Server, TempDir, TestFailure, check, check_equal,
    expect_reply, run_tests,
)

REFERENCE_MOTOR = ["--motor", "qbl4208-61-04-013"]
LATER_FIRMWARE = ["--firmware", "1.13"]
GIO = 15
JA, WAIT = 22, 27
STOP_APPLICATION, RUN_APPLICATION, RESET_APPLICATION = 128, 129, 131
DOWNLOAD, END_DOWNLOAD, APPLICATION_STATUS = 132, 133, 135  # 135: mode << 24 | ... (docs/decisions.md)
WAIT_TICKS = 0
STATUS_LOADED = 101  # an instruction stored in download mode
ACTUAL_VELOCITY = 42  # AP, rpm
TARGET_POSITION, ACTUAL_POSITION, REACHED_DISTANCE, POSITION_REACHED = 50, 52, 53, 55  # AP
RIGHT_SWITCH, LEFT_SWITCH, STATUS_FLAGS = 211, 212, 156  # AP
RIGHT_SWITCH_STOP, LEFT_SWITCH_STOP = 1 << 18, 1 << 19  # AP 156 bits (docs/tmcm-1636-servo.md)
TICK_TIMER = 132  # GP, simulated milliseconds


class LaterFirmwareServer(Server):
    """`motwin serve --firmware 1.13`: the firmware PyTrinamic's TMCM1636 class describes."""

    BANNER = r"motwin: tmcm-1636 \(1636V113\) eeprom (.+)"

    def __init__(self, motwin, state_dir, extra_args=(), **options):
        super().__init__(motwin, state_dir, extra_args=LATER_FIRMWARE + list(extra_args), **options)


# What the prints of PyTrinamic's feature objects read (GAP, axis 0), in their order: every one
# must answer with status 100 or the script stops with an exception.
DRIVE_SETTINGS_READS = (15, 14, 10, 12, 11, 25, 26, 54, 53)
DIGITAL_HALL_READS = (91, 90, 93, 92)
LINEAR_RAMP_READS = (43, 44, 45)
PID_READS = (70, 71, 72, 73, 74)
ABN_ENCODER_READS = (100, 101, 102)
ABSOLUTE_ENCODER_READS = (160, 162, 163, 161)


def print_settings(c, reads):
    for number in reads:
        c.gap(number)  # asserts status 100


def set_all(c, settings):
    for number, value in settings:
        c.sap(number, value)


def sim_ms(c):
    return c.ggp(TICK_TIMER, BANK_GLOBAL)


def move_to(c, target):
    expect_reply(c.request(MVP, MVP_ABS, 0, target), MVP, STATUS_OK, what=f"MVP ABS {target}")


SETTLE_BUDGET_MS = 3000  # simulated time after AP 55 first reads 1 for the motor to hold the target


def wait_position_reached(c, target, budget_ms):
    """The scripts' loop: GAP 55 until it is set, reading AP 50 and AP 52 every 0.2 s (here of
    simulated time), for at most `budget_ms` of simulated time. Then the motor must come to hold
    the target: within SETTLE_BUDGET_MS AP 55 stays set through half a second of samples and AP 52
    is within AP 53 of it. The flag alone may catch a motor passing through the window, slower
    than AP 54, and where the poll lands depends on how busy the host is: a single sample half a
    second later failed under load while the motor was still settling."""
    deadline_ms = sim_ms(c) + budget_ms
    positions = []
    while not c.gap(POSITION_REACHED):
        check_equal(c.gap(TARGET_POSITION), target, "AP 50 (target position)")
        positions.append(c.gap(ACTUAL_POSITION))
        if sim_ms(c) > deadline_ms:
            raise TestFailure(f"AP 55 not set within {budget_ms} ms of simulated time moving to {target}; "
                              f"the last positions {positions[-10:]}")
        c.wait_sim_ms(200)
    held_since_ms = None
    settle_deadline_ms = sim_ms(c) + SETTLE_BUDGET_MS
    while True:
        now_ms = sim_ms(c)
        if c.gap(POSITION_REACHED):
            held_since_ms = now_ms if held_since_ms is None else held_since_ms
            if now_ms - held_since_ms >= 500:
                break
        else:
            held_since_ms = None
        if now_ms > settle_deadline_ms:
            raise TestFailure(f"AP 55 not held for half a second within {SETTLE_BUDGET_MS} ms after it was set at "
                              f"{target}; AP 52 {c.gap(ACTUAL_POSITION)}")
        c.wait_sim_ms(50)
    position = c.gap(ACTUAL_POSITION)
    distance = c.gap(REACHED_DISTANCE)
    check(abs(position - target) <= distance, f"AP 52 {position} within AP 53 ({distance}) of {target}")


def calibrate_adc_offsets(c):
    """The script's first step: the mean of 40 raw readings of each phase ADC at rest becomes its
    offset, stored in the EEPROM."""
    for raw, offset in ((0, 5), (1, 6)):
        mean = round(sum(c.gap(raw) for _ in range(40)) / 40)
        c.sap(offset, mean)
        c.stap(offset)
        check(abs(c.gap(offset) - 32767) < 200, f"AP {offset} offset {c.gap(offset)} near mid-scale")


def test_encoder_velocity_mode(motwin):
    """encoder_velocity_mode.py: ABN commutation initialised from the halls, the examples' gains,
    ROR 2000 for four seconds (the motor turns at 2000 rpm), MST (it ramps down and stops)."""
    with TempDir() as tmp:
        with Server(motwin, os.path.join(tmp, "state"), extra_args=REFERENCE_MOTOR) as server:
            with server.tcp() as c:
                calibrate_adc_offsets(c)
                for number, value in ((14, 3), (10, 4), (11, 2000), (15, 3), (12, 1000),  # drive
                                      (91, 0), (90, 1), (93, 0),  # hall sensors
                                      (100, 4096), (101, 1), (102, 2),  # ABN encoder, aligned by the halls
                                      (43, 2000), (44, 1000), (45, 1),  # ramp
                                      (70, 300), (71, 600), (72, 100), (73, 100)):  # torque and velocity PI
                    c.sap(number, value)
                expect_reply(c.request(ROR, 0, 0, 2000), ROR, STATUS_OK, what="ROR 2000")
                c.wait_sim_ms(4000)
                velocity = c.gap(ACTUAL_VELOCITY)
                check(abs(velocity - 2000) <= 20, f"actual velocity {velocity} rpm after 4 s of ROR 2000")
                check_equal(c.gap(103), 0, "AP 103 (encoder initialisation state) done")
                expect_reply(c.request(MST), MST, STATUS_OK, what="MST")
                # The script sleeps 2 s, the time the ramp (AP 44, 1000 rpm/s) takes down from
                # 2000 rpm; the check leaves the regulator half a second more.
                c.wait_sim_ms(2500)
                velocity = c.gap(ACTUAL_VELOCITY)
                check(abs(velocity) <= 5, f"actual velocity {velocity} rpm 2.5 s after MST")
                c.sap(15, 0)
            server.stop()


def test_tmcl_script_load(motwin):
    """tmcl_script_load.py: downloads SAP 15, 0, 3; ROR 0, 500; WAIT ticks 100; ROR 0, -500;
    WAIT ticks 100; JA 1, resets and starts it: the motor turns one way, then the other, over
    and over, until the host stops the program and the motor."""
    program = ((5, 15, 0, 3), (ROR, 0, 0, 500), (WAIT, WAIT_TICKS, 0, 100), (ROR, 0, 0, -500),
               (WAIT, WAIT_TICKS, 0, 100), (JA, 0, 0, 1))
    with TempDir() as tmp:
        with Server(motwin, os.path.join(tmp, "state"), extra_args=REFERENCE_MOTOR) as server:
            with server.tcp() as c:
                expect_reply(c.request(DOWNLOAD), DOWNLOAD, STATUS_OK, what="start download")
                for command, type_, motor, value in program:
                    expect_reply(c.request(command, type_, motor, value), command, STATUS_LOADED,
                                 what=f"download of command {command}")
                expect_reply(c.request(END_DOWNLOAD), END_DOWNLOAD, STATUS_OK, what="end download")
                expect_reply(c.request(RESET_APPLICATION), RESET_APPLICATION, STATUS_OK, what="reset application")
                expect_reply(c.request(RUN_APPLICATION), RUN_APPLICATION, STATUS_OK, what="run application")
                # Forward, then backward, twice: the loop goes round. A window missed while the
                # machine stalls comes again two seconds later.
                for target in (500, -500, 500, -500):
                    c.wait_for(f"the motor at {target} rpm (the program's ROR {target})",
                               lambda: abs(c.gap(ACTUAL_VELOCITY) - target) <= 20, timeout=60.0)
                status = c.request(APPLICATION_STATUS)
                check_equal(status.status, STATUS_OK, "application status")
                check_equal(status.value >> 24, 1, "the program runs (135: mode 1)")
                expect_reply(c.request(STOP_APPLICATION), STOP_APPLICATION, STATUS_OK, what="stop application")
                expect_reply(c.request(MST), MST, STATUS_OK, what="MST")
                check_equal(c.request(APPLICATION_STATUS).value >> 24, 0, "the program stopped (135: mode 0)")
                c.wait_sim_ms(1000)
                velocity = c.gap(ACTUAL_VELOCITY)
                check(abs(velocity) <= 5, f"actual velocity {velocity} rpm after MST")
            server.stop()


# The examples' gains: torque P/I, velocity P/I, position P.
EXAMPLE_GAINS = ((70, 300), (71, 600), (72, 100), (73, 100), (74, 300))
HALL_AS_WIRED = ((91, 0), (90, 1), (93, 0), (92, 1))  # direction, polarity 1, offset, interpolation
# The position examples take up to 19 s of simulated time; --speed 4 shortens the wait.
FASTER = ["--speed", "4"]


def hall_example_setup(c):
    """What hall_position_mode.py and hall_digital_input.py send first: the drive, the halls as
    wired, the ramp, the position scaler (hall states per revolution) and the examples' gains,
    with the reads their prints make."""
    set_all(c, ((14, 3), (10, 4), (11, 2000), (15, 2), (53, 5), (54, 500)))
    print_settings(c, DRIVE_SETTINGS_READS)
    set_all(c, HALL_AS_WIRED)
    print_settings(c, DIGITAL_HALL_READS)
    set_all(c, ((43, 2000), (44, 1000), (45, 1)))
    print_settings(c, LINEAR_RAMP_READS)
    c.sap(56, 6 * c.gap(10))
    set_all(c, EXAMPLE_GAINS)
    print_settings(c, PID_READS)


def test_hall_position_mode(motwin):
    """hall_position_mode.py: hall commutation, the examples' gains, position scaler 6 x pole
    pairs, AP 52 = 0, MVP 0, then MVP 4000 and back to 0, each waiting for AP 55. A new MVP
    clears AP 55 at once, or the script's first wait would end before the motor moved."""
    with TempDir() as tmp:
        with LaterFirmwareServer(motwin, os.path.join(tmp, "state"), extra_args=REFERENCE_MOTOR + FASTER) as server:
            with server.tcp() as c:
                hall_example_setup(c)
                c.sap(ACTUAL_POSITION, 0)
                move_to(c, 0)
                check_equal(c.gap(POSITION_REACHED), 1, "AP 55 at rest on the target of MVP 0")
                move_to(c, 4000)
                check_equal(c.gap(POSITION_REACHED), 0, "AP 55 right after MVP 4000 (a new move clears it)")
                wait_position_reached(c, 4000, budget_ms=10000)
                move_to(c, 0)
                check_equal(c.gap(POSITION_REACHED), 0, "AP 55 right after MVP 0")
                wait_position_reached(c, 0, budget_ms=10000)
            server.stop()


def test_encoder_position_mode(motwin):
    """encoder_position_mode.py: ABN commutation (offset estimated, AP 102 = 0) with the examples'
    gains, position scaler = AP 100, AP 52 = 0, MVP to 50 revolutions and back, each waiting for
    AP 55."""
    with TempDir() as tmp:
        with LaterFirmwareServer(motwin, os.path.join(tmp, "state"), extra_args=REFERENCE_MOTOR + FASTER) as server:
            with server.tcp() as c:
                set_all(c, ((14, 3), (10, 4), (11, 2000), (15, 3), (53, 5), (54, 500), (12, 1000)))
                print_settings(c, DRIVE_SETTINGS_READS)
                set_all(c, ((100, 4096), (101, 1), (102, 0)))
                print_settings(c, ABN_ENCODER_READS)
                set_all(c, ((43, 2000), (44, 1000), (45, 1)))
                print_settings(c, LINEAR_RAMP_READS)
                c.sap(56, c.gap(100))
                set_all(c, EXAMPLE_GAINS)
                print_settings(c, PID_READS)
                c.wait_sim_ms(1000)
                c.sap(ACTUAL_POSITION, 0)
                target = c.gap(100) * 50
                move_to(c, target)
                check_equal(c.gap(POSITION_REACHED), 0, f"AP 55 right after MVP {target}")
                wait_position_reached(c, target, budget_ms=15000)
                move_to(c, 0)
                check_equal(c.gap(POSITION_REACHED), 0, "AP 55 right after MVP 0")
                wait_position_reached(c, 0, budget_ms=15000)
            server.stop()


# The bench of position_abn_abs.py: the reference motor with an AMT20 (12 bits) on its shaft,
# counting the way the script's AP 162 = 1 undoes, as its ABN encoder does for AP 101 = 1.
AMT20_MOTOR = '{"preset": "qbl4208-61-04-013", "absolute_encoder": {"bits": 12, "reversed": true}}\n'


def test_position_abn_abs(motwin):
    """position_abn_abs.py: ADC offsets, ABN commutation (AP 102 = 0), an AMT20 absolute encoder
    (AP 160 = 1) as the position sensor (AP 25 = 2), ramp 1000 rpm / 250 rpm/s, the motor's own
    gains; MVP 1000000 waits for AP 55; commutation and position sensor back to 0."""
    with TempDir() as tmp:
        motor_file = os.path.join(tmp, "qbl4208-amt20.json")
        with open(motor_file, "w") as f:
            f.write(AMT20_MOTOR)
        with LaterFirmwareServer(motwin, os.path.join(tmp, "state"), extra_args=["--motor", motor_file] + FASTER) as server:
            with server.tcp() as c:
                for raw, offset in ((0, 5), (1, 6)):
                    c.sap(offset, round(sum(c.gap(raw) for _ in range(40)) / 40))
                set_all(c, ((100, 4096), (101, 1), (102, 0)))
                print_settings(c, ABN_ENCODER_READS)
                set_all(c, ((160, 1), (161, 0), (162, 1), (163, 0)))
                print_settings(c, ABSOLUTE_ENCODER_READS)
                set_all(c, ((15, 3), (25, 2), (12, 1000)))
                print_settings(c, DRIVE_SETTINGS_READS)
                c.wait_sim_ms(1000)
                set_all(c, ((43, 1000), (44, 250)))
                print_settings(c, LINEAR_RAMP_READS)
                move_to(c, 1000000)
                check_equal(c.gap(POSITION_REACHED), 0, "AP 55 right after MVP 1000000")
                # 244 revolutions at 1000 rpm with 4 s ramps: about 19 s.
                wait_position_reached(c, 1000000, budget_ms=40000)
                set_all(c, ((15, 0), (25, 0)))
            server.stop()


def wait_switch(c, number, budget_ms):
    """The script's loop: GAP `number` every 0.1 s until it reads 1, for at most `budget_ms` of
    simulated time."""
    deadline_ms = sim_ms(c) + budget_ms
    while not c.gap(number):
        if sim_ms(c) > deadline_ms:
            raise TestFailure(f"AP {number} still 0 after {budget_ms} ms of simulated time; "
                              f"AP 52 {c.gap(ACTUAL_POSITION)}, AP 42 {c.gap(ACTUAL_VELOCITY)}")
        c.wait_sim_ms(100)


def check_stopped_at_switch(c, number, flag, what):
    """The enabled switch (AP 209) stops the motion towards it although the ROR still stands:
    the motor comes to rest and stays, AP 156 says why."""
    c.wait_sim_ms(300)
    resting = c.gap(ACTUAL_POSITION)
    c.wait_sim_ms(300)
    velocity = c.gap(ACTUAL_VELOCITY)
    check(abs(velocity) <= 5, f"actual velocity {velocity} rpm at the {what} switch")
    position = c.gap(ACTUAL_POSITION)
    tolerance = 10 * c.gap(56) / 4096  # 10 encoder counts in AP 52's units (AP 56 per revolution)
    check(abs(position - resting) <= tolerance, f"the motor stays at the {what} switch: AP 52 {resting}, then {position}")
    check_equal(c.gap(number), 1, f"AP {number} ({what} switch) while the motor rests on it")
    check(c.gap(STATUS_FLAGS) & flag, f"AP 156 says the {what} switch stops the motion")
    return position


def test_hall_endstop(motwin):
    """hall_endstop.py: hall commutation, reference switches enabled (AP 209 = 3) and low active
    (AP 210 = 0); ROR 500 until the right switch reads active, ROR -500 until the left one does,
    ROR 0. The bench: two switches three revolutions either side of the start that pull their
    inputs low when the rotor reaches them (REF_AT_LEVEL = 0)."""
    switches = ["--set", "REF_AT_LEVEL=0", "--set", "REF_R_AT=3", "--set", "REF_L_AT=-3"]
    with TempDir() as tmp:
        with LaterFirmwareServer(motwin, os.path.join(tmp, "state"), extra_args=REFERENCE_MOTOR + switches) as server:
            with server.tcp() as c:
                set_all(c, ((14, 3), (10, 4), (11, 2000), (15, 2)))
                print_settings(c, DRIVE_SETTINGS_READS)
                set_all(c, HALL_AS_WIRED)
                print_settings(c, DIGITAL_HALL_READS)
                set_all(c, ((209, 3), (210, 0)))
                check_equal((c.gap(RIGHT_SWITCH), c.gap(LEFT_SWITCH)), (0, 0), "AP 211, 212 between the switches")
                start = c.gap(ACTUAL_POSITION)
                expect_reply(c.request(ROR, 0, 0, 500), ROR, STATUS_OK, what="ROR 500")
                wait_switch(c, RIGHT_SWITCH, budget_ms=5000)
                right = check_stopped_at_switch(c, RIGHT_SWITCH, RIGHT_SWITCH_STOP, "right")
                # AP 52 counts AP 56 per revolution (the script leaves the factory 65536) from the
                # power-up angle of the rotor (40 degrees, 455 of 4096 encoder counts): the switch
                # at 3 revolutions is (3 x 4096 - 455) encoder counts away; stopping within 200
                # encoder counts past it.
                per_count = c.gap(56) / 4096
                switch_counts = (3 * 4096 - 455) * per_count
                check(0 <= right - start - switch_counts <= 200 * per_count,
                      f"stopped at AP 52 {right}, past the switch at {switch_counts}")
                expect_reply(c.request(ROR, 0, 0, -500), ROR, STATUS_OK, what="ROR -500")
                wait_switch(c, LEFT_SWITCH, budget_ms=5000)
                left = check_stopped_at_switch(c, LEFT_SWITCH, LEFT_SWITCH_STOP, "left")
                switch_counts = (-3 * 4096 - 455) * per_count
                check(0 <= switch_counts - (left - start) <= 200 * per_count,
                      f"stopped at AP 52 {left}, past the switch at {switch_counts}")
                check_equal(c.gap(RIGHT_SWITCH), 0, "AP 211 (right switch) released on the way back")
                expect_reply(c.request(ROR, 0, 0, 0), ROR, STATUS_OK, what="ROR 0")
            server.stop()


# The bench of hall_digital_input.py: two buttons on GPI0 and GPI1 whose inputs read 1 until
# pressed; someone presses the first at 4 s and the second at 7 s of simulated time.
PRESS_INPUT_0_MS, PRESS_INPUT_1_MS = 4000, 7000
BUTTONS = f"{PRESS_INPUT_0_MS / 1000} GPI0 0\n{PRESS_INPUT_1_MS / 1000} GPI1 0\n"


def turn_until_input_low(c, port, velocity, budget_ms):
    """ROR `velocity`, then the script's loop: while GIO `port` (bank 0) reads 1, AP 52 and AP 42
    every 0.2 s. Returns the positions and velocities it read."""
    expect_reply(c.request(ROR, 0, 0, velocity), ROR, STATUS_OK, what=f"ROR {velocity}")
    deadline_ms = sim_ms(c) + budget_ms
    positions, velocities = [], []
    while True:
        reply = expect_reply(c.request(GIO, port, 0), GIO, STATUS_OK, what=f"GIO {port}, 0")
        if reply.value != 1:
            return positions, velocities
        positions.append(c.gap(ACTUAL_POSITION))
        velocities.append(c.gap(ACTUAL_VELOCITY))
        if sim_ms(c) > deadline_ms:
            raise TestFailure(f"GIO {port} still 1 after {budget_ms} ms of simulated time")
        c.wait_sim_ms(200)


def test_hall_digital_input(motwin):
    """hall_digital_input.py: hall commutation with the examples' gains; ROR 500 until input 0
    is pressed (GIO 0 turns 0), ROR -500 until input 1 is, ROR 0."""
    with TempDir() as tmp:
        scenario = os.path.join(tmp, "buttons.scn")
        with open(scenario, "w") as f:
            f.write(BUTTONS)
        inputs = ["--set", "GPI0=1", "--set", "GPI1=1", "--scenario", scenario]
        with LaterFirmwareServer(motwin, os.path.join(tmp, "state"), extra_args=REFERENCE_MOTOR + inputs) as server:
            with server.tcp() as c:
                hall_example_setup(c)
                c.wait_sim_ms(1000)
                c.sap(ACTUAL_POSITION, 0)
                started_ms = sim_ms(c)
                check(started_ms < PRESS_INPUT_0_MS - 1500,
                      f"the set-up took until {started_ms} ms of simulated time; input 0 is pressed at {PRESS_INPUT_0_MS}")
                positions, velocities = turn_until_input_low(c, 0, 500, budget_ms=10000)
                check(sim_ms(c) >= PRESS_INPUT_0_MS, "the first phase ended when input 0 was pressed")
                check(any(abs(v - 500) <= 25 for v in velocities), f"500 rpm reached forwards: {velocities}")
                # AP 56 = 24: AP 52 counts hall steps, 24 per revolution; at least one revolution.
                check(positions and positions[-1] > 24, f"turned forwards: AP 52 {positions[-3:]}")
                turned_to = c.gap(ACTUAL_POSITION)
                positions, velocities = turn_until_input_low(c, 1, -500, budget_ms=10000)
                check(sim_ms(c) >= PRESS_INPUT_1_MS, "the second phase ended when input 1 was pressed")
                check(any(abs(v + 500) <= 25 for v in velocities), f"-500 rpm reached backwards: {velocities}")
                check(positions[-1] < turned_to - 24, f"turned backwards from {turned_to}: AP 52 {positions[-3:]}")
                expect_reply(c.request(ROR, 0, 0, 0), ROR, STATUS_OK, what="ROR 0")
                c.wait_sim_ms(1500)
                velocity = c.gap(ACTUAL_VELOCITY)
                check(abs(velocity) <= 5, f"actual velocity {velocity} rpm 1.5 s after ROR 0")
            server.stop()


if __name__ == "__main__":
    run_tests([test_encoder_velocity_mode, test_tmcl_script_load, test_hall_position_mode, test_encoder_position_mode,
               test_position_abn_abs, test_hall_endstop, test_hall_digital_input])
