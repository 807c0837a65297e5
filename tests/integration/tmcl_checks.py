"""TMCL protocol checks shared by the pty (pyserial) and the TCP (plain socket) tests.

Each check takes a connected client (motwin_harness.ClientBase) of a freshly started server
with an empty state directory, paced in real time (the motion checks watch the ramps), and
asserts every reply it gets.
"""

import time

from motwin_harness import (
    BANK_USER, DEFAULT_ACCELERATION, DEFAULT_MAX_VELOCITY, GAP, GET_VERSION, GGP, HOST_ADDRESS, MODULE_ADDRESS,
    MST, MVP, MVP_ABS, MVP_REL, RESET_MAGIC, ROL, ROR, RSAP, RSGP, SAP, SGP, SOFTWARE_RESET, STAP,
    STATUS_CHECKSUM, STATUS_INVALID_COMMAND, STATUS_INVALID_VALUE, STATUS_OK, STATUS_WRONG_TYPE, STGP,
    VERSION_BINARY, VERSION_STRING, check, check_equal, expect_reply, frame, parse_reply,
)


def check_version(c):
    check_equal(c.version_string(), VERSION_STRING, "136 type 0 version characters")
    expect_reply(c.request(GET_VERSION, 1), GET_VERSION, STATUS_OK, VERSION_BINARY, "136 type 1")
    # Test vector from docs/tmcl-protocol.md "Test vectors", byte for byte.
    check_equal(c.request_raw(frame(GET_VERSION, 1)).hex(" "), "02 01 64 88 06 64 01 09 63", "136 type 1 raw reply")
    expect_reply(c.request(GET_VERSION, 2), GET_VERSION, STATUS_WRONG_TYPE, what="136 type 2")
    # The version string reply must not have left stray bytes behind.
    c.expect_no_reply(0.1, "after the version replies")


def check_manual_vectors(c):
    """Frames printed in the manual (and docs/tmcl-protocol.md "Test vectors"), sent byte for byte."""
    # GAP 1, 0 (manual 2.6.6): AP 1 is a readable ADC value.
    r = parse_reply(c.request_raw(bytes.fromhex("01 06 01 00 00 00 00 00 08")))
    expect_reply(r, GAP, STATUS_OK, what="manual GAP 1, 0")
    # GGP 66, 0 (manual 2.6.10): the serial address, 1.
    r = parse_reply(c.request_raw(bytes.fromhex("01 0A 42 00 00 00 00 00 4D")))
    expect_reply(r, GGP, STATUS_OK, MODULE_ADDRESS, "manual GGP 66, 0")
    # STGP 42, 2 and RSGP 42, 2 (manual 2.6.11, 2.6.12).
    r = parse_reply(c.request_raw(bytes.fromhex("01 0B 2A 02 00 00 00 00 38")))
    expect_reply(r, STGP, STATUS_OK, what="manual STGP 42, 2")
    r = parse_reply(c.request_raw(bytes.fromhex("01 0C 2A 02 00 00 00 00 39")))
    expect_reply(r, RSGP, STATUS_OK, what="manual RSGP 42, 2")
    # ROR 0, 350 (docs/tmcl-protocol.md "Test vectors"): the reply echoes the value.
    raw = c.request_raw(bytes.fromhex("01 01 00 00 00 00 01 5E 61"))
    check_equal(raw.hex(" "), "02 01 64 01 00 00 01 5e c7", "reply to ROR 0, 350")
    check_equal(c.gap(40), 350, "AP 40 after ROR 0, 350")
    c.ok(MST)
    check_equal(c.gap(40), 0, "AP 40 after MST")


def check_parameter_round_trip(c):
    # SAP/GAP/STAP/RSAP on max velocity (AP 43, RWE).
    check_equal(c.gap(43), DEFAULT_MAX_VELOCITY, "AP 43 factory default")
    check_equal(c.gap(44), DEFAULT_ACCELERATION, "AP 44 factory default")
    c.sap(43, 3000)
    check_equal(c.gap(43), 3000, "AP 43 after SAP 3000")
    c.stap(43)
    c.sap(43, 1234)
    check_equal(c.gap(43), 1234, "AP 43 after SAP 1234")
    c.rsap(43)
    check_equal(c.gap(43), 3000, "AP 43 after RSAP (stored 3000)")
    # More E parameters: position reached distance/velocity, ADC offsets, a negative one.
    for number, stored, other in ((53, 17, 99), (54, 250, 1000), (5, 30000, 1), (6, 65535, 0), (93, -1234, 777)):
        c.sap(number, stored)
        check_equal(c.gap(number), stored, f"AP {number} after SAP {stored}")
        c.stap(number)
        c.sap(number, other)
        check_equal(c.gap(number), other, f"AP {number} after SAP {other}")
        c.rsap(number)
        check_equal(c.gap(number), stored, f"AP {number} after RSAP")
    # RSAP of a parameter never stored gives the factory default back.
    c.sap(44, 777)
    c.rsap(44)
    check_equal(c.gap(44), DEFAULT_ACCELERATION, "AP 44 after RSAP of a never stored value")

    # Errors: the protocol's status, the value echoed, nothing changed.
    expect_reply(c.request(SAP, 42, 0, 5), SAP, STATUS_WRONG_TYPE, 5, "SAP 42 (read-only)")
    expect_reply(c.request(SAP, 43, 0, 300000), SAP, STATUS_INVALID_VALUE, 300000, "SAP 43 out of range")
    check_equal(c.gap(43), 3000, "AP 43 after a rejected SAP")
    expect_reply(c.request(SAP, 43, 0, -1), SAP, STATUS_INVALID_VALUE, -1, "SAP 43 negative")
    expect_reply(c.request(GAP, 99), GAP, STATUS_WRONG_TYPE, what="GAP of an unknown parameter")
    expect_reply(c.request(STAP, 40), STAP, STATUS_WRONG_TYPE, what="STAP of a non-E parameter")
    expect_reply(c.request(RSAP, 42), RSAP, STATUS_WRONG_TYPE, what="RSAP of a read-only parameter")
    expect_reply(c.request(SAP, 43, 1, 100), SAP, STATUS_INVALID_VALUE, 100, "SAP on motor 1")
    expect_reply(c.request(GAP, 43, 1), GAP, STATUS_INVALID_VALUE, what="GAP on motor 1")
    expect_reply(c.request(99, 0, 0, 7), 99, STATUS_INVALID_COMMAND, 7, "unknown command 99")

    # User variables, bank 2.
    c.sgp(10, BANK_USER, -77)
    check_equal(c.ggp(10, BANK_USER), -77, "user variable 10")
    c.stgp(10, BANK_USER)
    c.sgp(10, BANK_USER, 5)
    check_equal(c.ggp(10, BANK_USER), 5, "user variable 10 after SGP 5")
    c.rsgp(10, BANK_USER)
    check_equal(c.ggp(10, BANK_USER), -77, "user variable 10 after RSGP")
    c.sgp(255, BANK_USER, 0x7FFFFFFF)
    check_equal(c.ggp(255, BANK_USER), 0x7FFFFFFF, "user variable 255")
    expect_reply(c.request(STGP, 56, BANK_USER), STGP, STATUS_WRONG_TYPE, what="STGP of user variable 56")
    expect_reply(c.request(RSGP, 56, BANK_USER), RSGP, STATUS_WRONG_TYPE, what="RSGP of user variable 56")


def _poll_velocity(c, target, timeout):
    """AP 42 samples until it equals `target`."""
    samples = []
    deadline = time.monotonic() + timeout
    while True:
        v = c.gap(42)
        samples.append(v)
        if v == target:
            return samples
        check(time.monotonic() < deadline, f"AP 42 did not reach {target} within {timeout} s: last samples {samples[-10:]}")
        time.sleep(0.005)


def _check_monotonic(samples, rising, what):
    for a, b in zip(samples, samples[1:]):
        check(b >= a if rising else b <= a, f"{what}: AP 42 not monotonic: {a} then {b} (samples {samples})")


def check_velocity_ramp(c):
    c.sap(44, 1000)  # 1000 rpm/s: the ramps below take most of a second each
    check_equal(c.gap(42), 0, "AP 42 at rest")
    expect_reply(c.request(ROR, 0, 0, 800), ROR, STATUS_OK, 800, "ROR 0, 800")
    check_equal(c.gap(40), 800, "AP 40 after ROR 800")
    up = _poll_velocity(c, 800, 10.0)
    _check_monotonic(up, True, "ROR 800")
    check(any(0 < v < 800 for v in up), f"ROR 800: no intermediate velocity seen (samples {up})")
    time.sleep(0.05)
    check_equal(c.gap(42), 800, "AP 42 holds the target velocity")
    position = c.gap(52)
    check(position > 0, f"AP 52 should have grown while turning right, is {position}")

    expect_reply(c.request(MST), MST, STATUS_OK, what="MST")
    check_equal(c.gap(40), 0, "AP 40 after MST")
    down = _poll_velocity(c, 0, 10.0)
    _check_monotonic(down, False, "MST")
    check(any(0 < v < 800 for v in down), f"MST: no intermediate velocity seen (samples {down})")
    time.sleep(0.05)
    check_equal(c.gap(42), 0, "AP 42 stays 0 after MST")

    expect_reply(c.request(ROL, 0, 0, 300), ROL, STATUS_OK, 300, "ROL 0, 300")
    check_equal(c.gap(40), -300, "AP 40 after ROL 300")
    left = _poll_velocity(c, -300, 10.0)
    _check_monotonic(left, False, "ROL 300")
    c.ok(MST)
    _poll_velocity(c, 0, 10.0)
    expect_reply(c.request(ROR, 0, 0, 300000), ROR, STATUS_INVALID_VALUE, 300000, "ROR beyond AP 40's range")
    expect_reply(c.request(ROR, 0, 1, 100), ROR, STATUS_INVALID_VALUE, 100, "ROR on motor 1")
    check_equal(c.gap(40), 0, "AP 40 after rejected ROR")


def _move_and_wait(c, target, timeout=15.0):
    """After an MVP: polls until AP 55 = 1 and AP 52 = target; the way there is monotonic and
    never overshoots the target."""
    start = c.gap(52)
    first_flag = c.gap(55)
    seen = []

    def reached():
        flag, position = c.gap(55), c.gap(52)
        seen.append((flag, position))
        return flag == 1 and position == target

    c.wait_for(f"AP 55 = 1 and AP 52 = {target}", reached, timeout)
    return first_flag, seen


def check_mvp_no_overshoot(c):
    """The ideal motor follows the ramp generator, which promises exact arrival without
    overshoot for a move from rest (src/core/motion/trapezoid_ramp.cpp): AP 52, polled as fast
    as the link allows, approaches the target monotonically and never passes it."""
    problems = []
    for target in (20000, 90000, -10000, 8192, 0, -20000):
        start = c.gap(52)
        direction = 1 if target >= start else -1
        c.ok(MVP, MVP_ABS, 0, target)
        positions = [start]
        at_target_since = None
        deadline = time.monotonic() + 15.0
        while at_target_since is None or time.monotonic() - at_target_since < 0.1:  # settled: 100 ms on target
            check(time.monotonic() < deadline, f"MVP {target}: not settled, last positions {positions[-10:]}")
            p = c.gap(52)
            positions.append(p)
            if p != target:
                at_target_since = None
            elif at_target_since is None:
                at_target_since = time.monotonic()
        check_equal(c.gap(55), 1, f"MVP {target}: AP 55 once settled")
        extreme = max(positions) if direction > 0 else min(positions)
        went_back = [(a, b) for a, b in zip(positions, positions[1:]) if (b - a) * direction < 0]
        if (extreme - target) * direction > 0 or went_back:
            problems.append(f"MVP ABS {start} -> {target}: reached {extreme} "
                            f"({(extreme - target) * direction} counts beyond), went back {went_back[:3]}")
    check(not problems, "AP 52 overshoots the MVP target: " + "; ".join(problems))


def check_position_move(c):
    c.sap(52, 0)
    check_equal(c.gap(52), 0, "AP 52 after SAP 52 0")
    r = expect_reply(c.request(MVP, MVP_ABS, 0, 20000), MVP, STATUS_OK, 20000, "MVP ABS 0, 20000")
    check_equal(c.gap(50), 20000, "AP 50 after MVP ABS 20000")
    first_flag, seen = _move_and_wait(c, 20000)
    check_equal(first_flag, 0, "AP 55 right after a long MVP")
    check(len(seen) > 1 and any(0 < p < 20000 for _, p in seen),
          f"MVP ABS 20000: no intermediate position seen ({seen[:10]})")
    time.sleep(0.05)
    check_equal(c.gap(52), 20000, "AP 52 stays at the target")
    check_equal(c.gap(42), 0, "AP 42 at the target")

    expect_reply(c.request(MVP, MVP_REL, 0, -30000), MVP, STATUS_OK, -30000, "MVP REL 0, -30000")
    check_equal(c.gap(50), -10000, "AP 50 after MVP REL -30000")
    _move_and_wait(c, -10000)
    c.ok(MVP, MVP_ABS, 0, -8192)
    _move_and_wait(c, -8192)
    expect_reply(c.request(MVP, MVP_ABS, 1, 5), MVP, STATUS_INVALID_VALUE, 5, "MVP on motor 1")
    expect_reply(c.request(MVP, 7, 0, 5), MVP, STATUS_WRONG_TYPE, 5, "MVP type 7")
    check_equal(c.gap(50), -8192, "AP 50 after rejected MVPs")


def check_software_reset(c):
    c.sap(43, 3500)
    c.stap(43)
    c.sap(44, 777)  # not stored: the stored value is the factory default
    c.sgp(10, BANK_USER, 4242)
    c.stgp(10, BANK_USER)
    c.sgp(11, BANK_USER, 5)  # storable but not stored
    c.sgp(60, BANK_USER, 99)  # not storable
    c.sap(52, 12345)
    # A wrong magic value: status 4, no reset.
    expect_reply(c.request(SOFTWARE_RESET, 0, 0, 1), SOFTWARE_RESET, STATUS_INVALID_VALUE, 1, "255 with value 1")
    check_equal(c.gap(44), 777, "AP 44 after a rejected reset")
    # The reset: reply first, then power-up.
    expect_reply(c.request(SOFTWARE_RESET, 0, 0, RESET_MAGIC), SOFTWARE_RESET, STATUS_OK, RESET_MAGIC, "255 with 1234")
    check_equal(c.gap(43), 3500, "stored AP 43 after reset")
    check_equal(c.gap(44), DEFAULT_ACCELERATION, "unstored AP 44 after reset")
    check_equal(c.ggp(10, BANK_USER), 4242, "stored user variable 10 after reset")
    check_equal(c.ggp(11, BANK_USER), 0, "unstored user variable 11 after reset")
    check_equal(c.ggp(60, BANK_USER), 0, "user variable 60 after reset")
    check_equal(c.gap(52), 0, "AP 52 after reset")
    check_equal(c.gap(40), 0, "AP 40 after reset")
    check_equal(c.version_string(), VERSION_STRING, "version after reset")


def check_checksum_error(c):
    bad = bytearray(frame(GAP, 43))
    bad[8] = (bad[8] + 1) & 0xFF
    raw = c.request_raw(bytes(bad))
    # Status 1, command 0, value 0 (docs/tmcl-protocol.md "Test vectors").
    check_equal(raw.hex(" "), "02 01 01 00 00 00 00 00 04", "reply to a checksum error")
    bad = bytearray(frame(SAP, 43, 0, 1111))
    bad[8] ^= 0x55
    r = parse_reply(c.request_raw(bytes(bad)))
    check_equal((r.host, r.module, r.status, r.command, r.value), (HOST_ADDRESS, MODULE_ADDRESS, STATUS_CHECKSUM, 0, 0),
                "checksum error on SAP")
    check(c.gap(43) != 1111, "a frame with a bad checksum must not execute")
    check_equal(c.gap(43), DEFAULT_MAX_VELOCITY, "AP 43 after bad-checksum SAP")
    c.expect_no_reply(0.1, "after checksum errors")


COMMON_CHECKS = [check_version, check_manual_vectors, check_parameter_round_trip, check_velocity_ramp,
                 check_position_move, check_software_reset, check_checksum_error]
