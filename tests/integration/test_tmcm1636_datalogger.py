#!/usr/bin/python3
"""Trinamic's TMCM-1636 datalogger examples (PyTrinamic, examples/modules/TMCM1636/TMCL/
datalogger_minimal.py and datalogger_demo.py) replayed frame by frame over TCP against
`motwin serve --firmware 1.13 --motor qbl4208-61-04-013`: the 142 requests PyTrinamic's
DataLogger sends for them (docs/datalogger.md "What a host sends"), written from what the scripts
do. The demo runs while the motor turns, so that its two channels can be checked against each
other: the velocity near the commanded one, the position advancing by velocity x sample period.
The same command over the pseudo-terminal and over TMCL on CAN, and command 157.
"""

import os
import struct
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from can_bus_harness import BusServer, TmclCan, open_bus  # noqa: E402
from motwin_harness import (  # noqa: E402
    MST, ROR, STATUS_OK, Server, TempDir, check, check_equal, expect_reply, run_tests,
)

RAMDEBUG, GET_INFO_COMMAND = 142, 157
INIT, SAMPLE_COUNT, PRESCALER, CHANNEL, ENABLE_TRIGGER, STATE, SAMPLE, INFO = 0, 1, 3, 4, 7, 8, 9, 10
AXIS_PARAMETER = 1  # channel type
COMPLETE = 3
STATUS_MAX_EXCEEDED = 9
ADC_PHASE_A, ACTUAL_VELOCITY, ACTUAL_POSITION = 0, 42, 52  # APs
REFERENCE_SETUP = ["--firmware", "1.13", "--motor", "qbl4208-61-04-013"]


class Server113(Server):
    BANNER = r"motwin: tmcm-1636 \(1636V113\) eeprom (.+)"


def ramdebug(c, type_, motor=0, value=0, status=STATUS_OK):
    return expect_reply(c.request(RAMDEBUG, type_, motor, value), RAMDEBUG, status,
                        what=f"142 type {type_} motor {motor} value {value}")


def unsigned(value):
    return value & 0xFFFFFFFF  # the host reads every sample as an unsigned word


def signed(word):
    return struct.unpack(">i", struct.pack(">I", word))[0]


def get_info(c):
    """DataLogger.get_info(): ids 4, 2, 1, 0. Id 4 (the link's samples per second) is not
    answered, which the host takes as "no limit"."""
    ramdebug(c, INFO, value=4, status=STATUS_MAX_EXCEEDED)
    base_hz = ramdebug(c, INFO, value=2).value
    buffer_words = ramdebug(c, INFO, value=1).value
    channels = ramdebug(c, INFO, value=0).value
    check_equal((base_hz, buffer_words, channels), (2000, 8192, 4), "info: base rate, buffer, channels")
    return base_hz, buffer_words, channels


def capture(c, samples_per_channel, prescaler, aps):
    """start_capture() without a trigger, wait_for_capture_completion(), download_log(): the raw
    words, channel k at k::len(aps)."""
    get_info(c)
    ramdebug(c, INIT)
    ramdebug(c, SAMPLE_COUNT, value=samples_per_channel * len(aps))
    ramdebug(c, PRESCALER, value=prescaler)
    for ap in aps:
        ramdebug(c, CHANNEL, AXIS_PARAMETER, ap)
    ramdebug(c, ENABLE_TRIGGER, 0, 0)
    # The host polls without pause; the condition is the module's (simulated) clock reaching the
    # end of the capture, the timeout only a guard against a hang.
    c.wait_for("the capture to complete (state 3)", lambda: ramdebug(c, STATE).value == COMPLETE,
               timeout=120.0, interval=0)
    total = samples_per_channel * len(aps)
    words = [unsigned(ramdebug(c, SAMPLE, value=i).value) for i in range(total)]
    ramdebug(c, SAMPLE, value=total, status=STATUS_MAX_EXCEEDED)
    return words


def test_datalogger_minimal(motwin):
    """datalogger_minimal.py: ten samples of AP 0 (ADC phase A raw) at the full base rate."""
    with TempDir() as tmp:
        with Server113(motwin, os.path.join(tmp, "state"), extra_args=REFERENCE_SETUP) as server:
            with server.tcp() as c:
                words = capture(c, 10, 0, [ADC_PHASE_A])
                check_equal(len(words), 10, "samples downloaded")
                for word in words:
                    check(abs(word - 32767) < 1000, f"ADC phase A {word} at rest near mid-scale")
                # The noise (sigma 8 mA) is half an ADC step (16 counts): ten samples are all alike
                # about once in fifty captures, 200 never in practice.
                words = capture(c, 200, 0, [ADC_PHASE_A])
                check(len(set(words)) > 1, f"the ADC's noise shows in the samples: {words}")
            server.stop()


def test_datalogger_demo_while_turning(motwin):
    """datalogger_demo.py: AP 42 and AP 52, 1024 samples each at 1000 Hz (down-sampling 2), here
    while the motor turns at 1000 rpm in ABN encoder velocity mode (the encoder example's
    settings, a 4096-count encoder). Firmware 1.13 counts AP 52 in AP 56 units per revolution."""
    with TempDir() as tmp:
        with Server113(motwin, os.path.join(tmp, "state"), extra_args=REFERENCE_SETUP) as server:
            with server.tcp() as c:
                get_info(c)  # the demo's own print-out of the figures
                for raw, offset in ((0, 5), (1, 6)):
                    c.sap(offset, round(sum(c.gap(raw) for _ in range(40)) / 40))
                for number, value in ((14, 3), (10, 4), (11, 2000), (15, 3), (12, 1000),
                                      (91, 0), (90, 1), (93, 0), (100, 4096), (101, 1), (102, 2),
                                      (43, 2000), (44, 1000), (45, 1), (70, 300), (71, 600), (72, 100), (73, 100)):
                    c.sap(number, value)
                expect_reply(c.request(ROR, 0, 0, 1000), ROR, STATUS_OK, what="ROR 1000")
                c.wait_for("the motor at 1000 rpm", lambda: abs(c.gap(ACTUAL_VELOCITY) - 1000) <= 10, timeout=120.0)
                c.wait_sim_ms(500)
                words = capture(c, 1024, 1, [ACTUAL_VELOCITY, ACTUAL_POSITION])
                check_equal(len(words), 2048, "samples downloaded")
                velocity = [signed(w) for w in words[0::2]]
                position = [signed(w) for w in words[1::2]]
                for v in velocity:
                    check(abs(v - 1000) <= 30, f"velocity sample {v} rpm near 1000")
                # 1 ms per sample: velocity / 60 revolutions of AP 56 units.
                per_revolution = c.gap(56)
                steps = [b - a for a, b in zip(position, position[1:])]
                mean_step = sum(steps) / len(steps)
                expected = 1000 / 60 * per_revolution * 0.001
                check(abs(mean_step - expected) < 0.02 * expected,
                      f"position advances {mean_step:.2f} units per sample, velocity x period {expected:.2f}")
                for i, step in enumerate(steps):
                    step_expected = (velocity[i] + velocity[i + 1]) / 2 / 60 * per_revolution * 0.001
                    check(abs(step - step_expected) <= 6 / 4096 * per_revolution,  # 6 encoder counts
                          f"position step {i}: {step}, velocity says {step_expected:.1f}")
                expect_reply(c.request(MST), MST, STATUS_OK, what="MST")
            server.stop()


def test_datalogger_over_a_pseudo_terminal(motwin):
    """The minimal example's frames over the pty link (what `serial_tmcl` uses)."""
    with TempDir() as tmp:
        link = os.path.join(tmp, "tmcm1636")
        with Server113(motwin, os.path.join(tmp, "state"), tcp=False, pty_link=link,
                       extra_args=REFERENCE_SETUP) as server:
            with server.serial() as c:
                words = capture(c, 10, 0, [ADC_PHASE_A])
                for word in words:
                    check(abs(word - 32767) < 1000, f"ADC phase A {word} at rest near mid-scale")
            server.stop()


def test_datalogger_over_can(motwin):
    """A capture of AP 52 and GP 132 (the tick timer) over TMCL on CAN, on firmware 1.09 (the
    default): 20 rows at 100 Hz (prescaler 19) span 190 ms of the module's clock."""
    with TempDir() as tmp:
        server = BusServer(motwin, os.path.join(tmp, "state"), ["--module", "tmcm-1636", "--can", "socketcand:127.0.0.1:0"])
        with server:
            bus = open_bus(server.port())
            try:
                tmcl = TmclCan(bus)
                check_equal(tmcl.ok(RAMDEBUG, INFO, 0, 2), 2000, "info 2 over CAN")
                tmcl.ok(RAMDEBUG, INIT)
                tmcl.ok(RAMDEBUG, SAMPLE_COUNT, 0, 40)
                tmcl.ok(RAMDEBUG, PRESCALER, 0, 19)
                tmcl.ok(RAMDEBUG, CHANNEL, AXIS_PARAMETER, ACTUAL_POSITION)
                tmcl.ok(RAMDEBUG, CHANNEL, 8, 132)  # GP 132, bank 0
                tmcl.ok(RAMDEBUG, ENABLE_TRIGGER, 0, 0)
                deadline = time.monotonic() + 60.0
                while tmcl.ok(RAMDEBUG, STATE) != COMPLETE:
                    check(time.monotonic() < deadline, "the capture completes within 60 s")
                words = [tmcl.ok(RAMDEBUG, SAMPLE, 0, i) for i in range(40)]
                ticks_ms = words[1::2]
                check_equal(ticks_ms[-1] - ticks_ms[0], 190, "tick timer across 20 rows at 100 Hz (ms)")
                check(all(p == words[0] for p in words[0::2]), f"the idle motor's position stays: {words[0::2]}")
                check_equal(tmcl.request(RAMDEBUG, SAMPLE, 0, 40)[1], STATUS_MAX_EXCEEDED, "index 40 of 40")
            finally:
                bus.shutdown()
            server.stop()


def test_get_info_157(motwin):
    """Command 157 as TmclInterface.get_info() sends it: module id, version, capabilities,
    release type; an entry the module lacks answers status 3."""
    with TempDir() as tmp:
        with Server113(motwin, os.path.join(tmp, "state"), extra_args=REFERENCE_SETUP) as server:
            with server.tcp() as c:
                for entry, value in ((0, 1636), (1, 0x0001000D), (2, 0x02), (3, 0), (20, 8)):
                    expect_reply(c.request(GET_INFO_COMMAND, entry), GET_INFO_COMMAND, STATUS_OK, value,
                                 what=f"157 entry {entry}")
                for entry in (10, 11, 21, 30):
                    expect_reply(c.request(GET_INFO_COMMAND, entry), GET_INFO_COMMAND, 3, what=f"157 entry {entry}")
            server.stop()


if __name__ == "__main__":
    run_tests([test_datalogger_minimal, test_datalogger_demo_while_turning, test_datalogger_over_a_pseudo_terminal,
               test_datalogger_over_can, test_get_info_157])
