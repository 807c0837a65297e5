#!/usr/bin/python3
"""Trinamic's TMCM-1636 example scripts (PyTrinamic, examples/modules/TMCM1636/TMCL/) replayed
over TCP against `motwin serve --motor qbl4208-61-04-013`, the reference motor the scripts name:
the same parameter sequence the scripts send, and the outcome they wait for. Written from what
the scripts do (docs/tmcm-1636-servo.md "Presets"); these two need nothing beyond the V1.09
firmware. The motion examples that print `drive_settings` read AP 26 of a later firmware and are
not replayed yet.
"""

import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from motwin_harness import (  # noqa: E402
    MST, ROR, STATUS_OK, Server, TempDir, check, check_equal, expect_reply, run_tests,
)

REFERENCE_MOTOR = ["--motor", "qbl4208-61-04-013"]
JA, WAIT = 22, 27
STOP_APPLICATION, RUN_APPLICATION, RESET_APPLICATION = 128, 129, 131
DOWNLOAD, END_DOWNLOAD, APPLICATION_STATUS = 132, 133, 135  # 135: mode << 24 | ... (docs/decisions.md)
WAIT_TICKS = 0
STATUS_LOADED = 101  # an instruction stored in download mode
ACTUAL_VELOCITY = 42  # AP, rpm


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


if __name__ == "__main__":
    run_tests([test_encoder_velocity_mode, test_tmcl_script_load])
