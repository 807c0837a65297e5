#!/usr/bin/python3
"""TMCL programs on the TMCM-142 with `motwin run --module tmcm-142`: the manual's example
program (section 5.2, test2.tmc) with its positions and speeds, and a program that reacts to
an encoder deviation stop (JC EDV) on a blocked rotor of the NEMA23 model (scenario BLOCKED).

Speeds are in TMC457 units (AP 255 = 0): 500000 units = 7450.58 microsteps/s.
"""

import csv
import io
import os
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from motwin_harness import TempDir, check, check_equal, run_tests  # noqa: E402

PROGRAMS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "programs")
PPS_PER_UNIT = 64e6 / 2 ** 32
REV = 204800


def motwin_run(motwin, *args):
    result = subprocess.run([motwin, "run", *args, "--module", "tmcm-142", "--trace", "-"], stdin=subprocess.DEVNULL,
                            capture_output=True, text=True, timeout=120)
    check(result.returncode == 0, f"motwin run {' '.join(args)}: exit status {result.returncode}\n"
                                  f"stdout: {result.stdout}\nstderr: {result.stderr}")
    rows = list(csv.reader(io.StringIO(result.stdout)))
    return rows[0], [[float(v) if i == 0 else int(v) for i, v in enumerate(row)] for row in rows[1:]], result.stderr


def test_manual_example_5_2(motwin):
    """ROL 500000 for 5 s, ROR 250000 for 5 s, then MVP ABS between +-1000000 at VMAX 500000."""
    header, rows, report = motwin_run(motwin, os.path.join(PROGRAMS, "tmcm142_5_2_test2.tmc"), "--for", "450s",
                                      "--sample", "1s", "--param", "0,1,3,4")
    check_equal(header, ["time_s", "AP0", "AP1", "AP3", "AP4"], "trace header")
    check_equal(len(rows), 451, "a sample each second from 0 to 450 s")
    check("program: still running at the end" in report, f"the loop runs on: {report!r}")
    at = {round(row[0]): row for row in rows}
    speed = 500000 * PPS_PER_UNIT  # 7450.58 microsteps/s
    # ROL: full speed left after the ramp; 5 s at that speed less what the ramp took.
    for t in (1, 2, 3, 4):
        check_equal(at[t][3], -500000, f"actual speed at {t} s (ROL 0, 500000)")
    check(-5 * speed <= at[5][2] <= -5 * speed + 0.1 * speed, f"position after the ROL phase: {at[5][2]}")
    for t in (6, 7, 8, 9):
        check_equal(at[t][3], 250000, f"actual speed at {t} s (ROR 0, 250000)")
    # The ROR phase took back half of it, less the stop from -speed and the ramps (about 0.1 s).
    ror_travel = at[10][2] - at[5][2]
    check(2.4 * speed <= ror_travel <= 2.5 * speed, f"ROR travel: {ror_travel}")
    check_equal(at[12][4], 500000, "SAP 4, 0, 500000")
    check_equal(at[12][3], 500000, "moving at VMAX towards +1000000")
    # First leg: from the end of the ROR phase to 1000000 at VMAX. WAIT POS ends on arrival and the
    # next MVP makes the target -1000000 at once: the first sample with that target dates the arrival.
    arrive_up = 10 + (1000000 - at[10][2]) / speed
    turn_up = next(row for row in rows if row[1] == -1000000)
    check(arrive_up <= turn_up[0] <= arrive_up + 1.1,
          f"arrival at 1000000 at {turn_up[0]} s, expected ~{arrive_up:.1f}")
    check(1000000 - speed <= turn_up[2] <= 1000000, f"just past the turn at 1000000: {turn_up}")
    # Second leg: 2000000 microsteps down to -1000000, then the loop turns up again.
    arrive_down = turn_up[0] + 2000000 / speed
    turn_down = next(row for row in rows if row[0] > turn_up[0] and row[1] == 1000000)
    check(arrive_down - 1.1 <= turn_down[0] <= arrive_down + 1.1,
          f"arrival at -1000000 at {turn_down[0]} s, expected ~{arrive_down:.1f}")
    check(-1000000 <= turn_down[2] <= -1000000 + speed, f"just past the turn at -1000000: {turn_down}")
    check_equal(rows[-1][1], 1000000, "third leg under way: the target is +1000000 again")
    check(-1000000 < rows[-1][2] < 1000000 and rows[-1][3] == 500000, f"third leg at VMAX: {rows[-1]}")
    check(all(-1000000 <= row[2] <= 1000000 for row in rows), "never beyond the targets")


def test_jc_edv_on_a_blocked_rotor(motwin):
    with TempDir() as tmp:
        scenario = os.path.join(tmp, "blocked.txt")
        with open(scenario, "w") as f:
            f.write("0 BLOCKED 1\n")
        header, rows, report = motwin_run(motwin, os.path.join(PROGRAMS, "tmcm142_edv_stop.tmc"), "--motor", "nema23",
                                          "--scenario", scenario, "--for", "1s", "--sample", "100ms",
                                          "--param", "1,41", "--var", "0,1,2")
        check_equal(header, ["time_s", "AP1", "AP41", "var0", "var1", "var2"], "trace header")
        last = rows[-1]
        check_equal(last[3], 1, "var 0: the program took the JC EDV branch")
        check(2000 < last[4] - last[5] <= 2060,
              f"stopped just past the 2000 microstep limit: AP 1 {last[4]}, AP 41 {last[5]}")
        check(abs(last[5]) <= 60, f"the blocked rotor did not turn: encoder {last[5]}")
        check_equal((last[1], last[2]), (last[4], last[5]), "recorded positions are where the axis stands")
        check("STOP instruction" in report, f"the program stopped: {report!r}")


def test_default_trace_columns_are_position_and_speed(motwin):
    header, rows, _ = motwin_run(motwin, os.path.join(PROGRAMS, "tmcm142_5_2_test2.tmc"), "--for", "1s",
                                 "--sample", "500ms")
    check_equal(header, ["time_s", "AP1", "AP3"], "default columns on the TMCM-142")
    check_equal(rows[-1][2], -500000, "ROL 0, 500000 under way at 1 s")


if __name__ == "__main__":
    run_tests([test_manual_example_5_2, test_jc_edv_on_a_blocked_rotor,
               test_default_trace_columns_are_position_and_speed])
