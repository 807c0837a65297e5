#!/usr/bin/python3
"""`motwin serve --module tmcm-142`: the TMCM-142 as a running virtual module.

Covers: the banner, version and TMCL over TCP and over CAN; the I/O signals (IN/AIN via GIO, OUT
via SIO and the `output` lines); an ASCII session on the pseudo-terminal that homes the axis with
RFS against switches placed by a scenario, stores coordinates with SCO, moves between them with
MVP COORD and runs into the right limit switch (hard stop: the target becomes the stop point);
a blocked rotor (scenario BLOCKED, NEMA23 model) with AP 212 set stopping the motor and flagging
AP 207 / AP 129; a start-up error for a motor the module cannot drive.

Positions are in microsteps at the default 1024 per full step: 204800 per revolution of the
200-step motor. The encoder (AP 41) has 4000 counts per revolution: 51.2 microsteps per count.
"""

import os
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from can_bus_harness import BusServer, TmclCan, open_bus  # noqa: E402
from motwin_harness import (  # noqa: E402
    MVP, SerialClient, TcpClient, TempDir, check, check_equal, expect_reply, run_tests,
)

REV = 204800          # microsteps per revolution
ENCODER_STEP = 51.2   # microsteps per encoder count
SIO, GIO, RFS, SCO, GCO, CCO = 14, 15, 13, 30, 31, 32
ENTER_ASCII = 139
MVP_COORD = 2
# Generous: realtime simulation of moves of a few seconds, also under a slow sanitizer build.
MOVE_TIMEOUT = 30.0


def serve(motwin, tmp, *extra, pty=False, scenario=None):
    args = ["--module", "tmcm-142", "--tmcl-tcp", "127.0.0.1:0"]
    if pty:
        args += ["--tmcl-pty", os.path.join(tmp, "tmcm142")]
    if scenario is not None:
        path = os.path.join(tmp, "scenario.txt")
        with open(path, "w") as f:
            f.write(scenario)
        args += ["--scenario", path]
    return BusServer(motwin, os.path.join(tmp, "state"), args + list(extra))


def tcp_client(server):
    return TcpClient(server.tcp_port_of())


# --- ASCII helpers ----------------------------------------------------------------------------

def read_line(client, what):
    data = b""
    while not data.endswith(b"\r"):
        data += client.read_exact(1)
        check(len(data) < 200, f"{what}: no CR in {data!r}")
    return data[:-1].decode("latin-1")


def ascii_command(client, text):
    """Sends one line (default echo: every character comes back), returns (status, value)."""
    client.send_raw(text.encode("latin-1") + b"\r")
    check_equal(read_line(client, text), text, f"echo of {text!r}")
    reply = read_line(client, text).split()
    check(len(reply) == 3 and reply[0] == "BA", f"{text}: reply {reply!r}")
    return int(reply[1]), int(reply[2])


def ascii_ok(client, text):
    status, value = ascii_command(client, text)
    check_equal(status, 100, f"status of {text!r}")
    return value


def ascii_wait(client, text, predicate, timeout, what):
    deadline = time.monotonic() + timeout
    while True:
        value = ascii_ok(client, text)
        if predicate(value):
            return value
        check(time.monotonic() < deadline, f"timed out after {timeout} s waiting for {what} (last {text}: {value})")
        time.sleep(0.02)


def check_near(actual, expected, tolerance, what):
    check(abs(actual - expected) <= tolerance, f"{what}: expected {expected} +- {tolerance}, got {actual}")


# --- Tests ------------------------------------------------------------------------------------

def test_identity_io_and_can(motwin):
    """Version over TCP and CAN; GIO reads the --set inputs, SIO drives OUT0 (logged)."""
    with TempDir() as tmp:
        server = serve(motwin, tmp, "--can", "socketcand:127.0.0.1:0", "--set", "IN4=1", "--set", "AIN1=3000",
                       "--set", "AIN2=1000", "--set", "IN0=1")
        with server:
            check_equal(server.banners[0][1:3], ("tmcm-142", "142V1.06"), "banner")
            with tcp_client(server) as client:
                check_equal(client.version_string(), b"142V1.06", "version string")
                check_equal(client.ok(136, 1).value, 0x008E0106, "binary version")
                # Digital bank 0: IN4 set, IN1 follows AIN1 (above half scale), IN2 does not.
                levels = [client.ok(GIO, port, 0).value for port in range(9)]
                check_equal(levels, [1, 1, 0, 0, 1, 0, 0, 0, 0], "IN0..IN8")
                check_equal([client.ok(GIO, port, 1).value for port in range(3)], [4095, 3000, 1000], "AIN0..AIN2")
                check_equal(client.request(GIO, 9, 0).status, 3, "GIO of IN9: wrong type")
                client.ok(SIO, 2, 2, 1)
                check_equal(client.ok(GIO, 2, 2).value, 1, "OUT2 reads back")
                check_equal(client.request(SIO, 3, 2, 1).status, 3, "SIO OUT3: wrong type")
                # Defaults of the module profile over the same link.
                check_equal(client.gap(4), 13743895, "AP 4 default (1 rev/s at 1024 microsteps)")
            bus = open_bus(server.port())
            try:
                tmcl = TmclCan(bus)
                check_equal(tmcl.request_raw([136, 0, 0, 0, 0, 0, 0]), b"142V1.06", "version over CAN")
                check_equal(tmcl.ok(15, 4, 0), 1, "GIO IN4 over CAN")
            finally:
                bus.shutdown()
            deadline = time.monotonic() + 10  # printed at the next tick; a loaded machine may lag
            while not any(line.startswith("output OUT2 1 at ") for line in server.stdout_lines):
                check(time.monotonic() < deadline, f"no output line for OUT2: {server.stdout_lines!r}")
                time.sleep(0.02)
            server.stop()


def test_ascii_homing_and_coordinates(motwin):
    """Ideal motor; left switch closed at rotor <= -0.25 rev, right one at >= 1.5 rev (scenario)."""
    scenario = "0 REF_L_AT -0.25   # left limit switch, a quarter revolution below the start\n" \
               "0 REF_R_AT 1.5\n"
    with TempDir() as tmp:
        server = serve(motwin, tmp, pty=True, scenario=scenario)
        with server:
            with SerialClient(server.endpoints["tmcl-pty"][0][0]) as client:
                expect_reply(client.request(ENTER_ASCII), ENTER_ASCII, 100, 0, "139 (enter ASCII mode)")
                check_equal(ascii_ok(client, "AGAP 11, 0"), 0, "left switch open at the start")
                # RFS mode 1: fast to the left switch, slowly out of it; that point is 0.
                ascii_ok(client, "ASAP 193, 0, 1")
                check_equal(ascii_ok(client, "ARFS START, 0"), 0, "RFS START")
                ascii_wait(client, "ARFS STATUS, 0", lambda v: v == 0, MOVE_TIMEOUT, "the end of the reference search")
                check_equal(ascii_ok(client, "AGAP 1, 0"), 0, "actual position after homing")
                check_equal(ascii_ok(client, "AGAP 3, 0"), 0, "at rest after homing")
                check_equal(ascii_ok(client, "AGAP 11, 0"), 0, "left switch open at the home point")
                # The rotor stands at the switch: the encoder counted a quarter revolution down.
                home_encoder = ascii_ok(client, "AGAP 41, 0")
                check_near(home_encoder, -REV // 4, ENCODER_STEP, "encoder at the home point")

                # Coordinates 1 and 2; MVP COORD moves to them.
                ascii_ok(client, "ASCO 1, 0, 102400")
                ascii_ok(client, "ASCO 2, 0, 25600")
                check_equal(ascii_ok(client, "AGCO 1, 0"), 102400, "GCO 1")
                for number, target in [(1, 102400), (2, 25600), (1, 102400)]:
                    ascii_ok(client, f"AMVP COORD, 0, {number}")
                    ascii_wait(client, "AGAP 8, 0", lambda v: v == 1, MOVE_TIMEOUT, f"arrival at coordinate {number}")
                    check_equal(ascii_ok(client, "AGAP 1, 0"), target, f"position at coordinate {number}")
                    check_equal(ascii_ok(client, "AGAP 0, 0"), target, f"target of MVP COORD {number}")
                    check_near(ascii_ok(client, "AGAP 41, 0") - home_encoder, target, ENCODER_STEP,
                               f"encoder travel to coordinate {number}")
                check_equal(ascii_command(client, "AMVP COORD, 0, 21")[0], 4, "MVP COORD 21: invalid value")

                # Into the right switch (rotor 1.5 rev = 1.75 rev from home): a hard stop there, and
                # the stop point becomes the target (AP 8 set, AP 0 = AP 1).
                ascii_ok(client, "AMVP ABS, 0, 500000")
                ascii_wait(client, "AGAP 10, 0", lambda v: v == 1, MOVE_TIMEOUT, "the right switch")
                ascii_wait(client, "AGAP 3, 0", lambda v: v == 0, MOVE_TIMEOUT, "the stop at the right switch")
                stop = ascii_ok(client, "AGAP 1, 0")
                check(int(1.75 * REV) <= stop <= int(1.75 * REV) + 40, f"stopped at the switch: {stop}")
                check_equal(ascii_ok(client, "AGAP 0, 0"), stop, "target after the hard stop")
                check_equal(ascii_ok(client, "AGAP 8, 0"), 1, "position reached after the hard stop")
                # Capture it, and move away from the switch (always possible) back to coordinate 2.
                ascii_ok(client, "ACCO 3, 0")
                check_equal(ascii_ok(client, "AGCO 3, 0"), stop, "CCO 3 captured the stop point")
                ascii_ok(client, "AMVP COORD, 0, 2")
                ascii_wait(client, "AGAP 8, 0", lambda v: v == 1, MOVE_TIMEOUT, "arrival back at coordinate 2")
                check_equal(ascii_ok(client, "AGAP 1, 0"), 25600, "back at coordinate 2")
                check_equal(ascii_ok(client, "AGAP 10, 0"), 0, "right switch open again")
                # Coordinates copied to the EEPROM image (GP 84 = 0: on request).
                ascii_ok(client, "ASCO 0, 255, 0")
                ascii_ok(client, "ABIN")
            server.stop()
        # After a restart on the same state directory, GCO n, 255 brings the stored copies back.
        server = serve(motwin, tmp)
        with server:
            with tcp_client(server) as client:
                check_equal(client.ok(GCO, 1, 0).value, 0, "RAM coordinate 1 after power-up")
                client.ok(GCO, 0, 255)
                check_equal([client.ok(GCO, n, 0).value for n in (1, 2, 3)], [102400, 25600, stop],
                            "coordinates restored from the EEPROM copy")
            server.stop()


def test_blocked_rotor_stops_with_encoder_deviation(motwin):
    """NEMA23 model, rotor blocked from the start: every step is lost; AP 212 stops the move."""
    with TempDir() as tmp:
        server = serve(motwin, tmp, "--motor", "nema23", scenario="0 BLOCKED 1   # an obstacle\n")
        with server:
            with tcp_client(server) as client:
                client.sap(212, 2000)
                check_equal(client.gap(207), 0, "no error flags before the move")
                client.ok(MVP, 0, 0, 3 * REV)
                client.wait_for("the deviation stop", lambda: client.gap(129) & 8, MOVE_TIMEOUT)
                client.wait_for("rest", lambda: client.gap(3) == 0, MOVE_TIMEOUT)
                actual = client.gap(1)
                encoder = client.gap(41)
                check(abs(encoder) <= 60, f"the blocked rotor did not turn: encoder {encoder}")
                check(2000 < actual - encoder <= 2000 + 60, f"stopped just past the deviation limit: AP 1 {actual}")
                check_equal(client.gap(0), actual, "target after the deviation stop")
                check_equal(client.gap(207), 2, "AP 207 bit 1: stopped by the encoder deviation")
                # An event, not the condition: it stays cleared while the deviation lasts
                # (thousands of ticks between these reads), AP 129 bit 3 shows the condition.
                client.wait_sim_ms(100)
                check_equal(client.gap(207), 0, "AP 207 cleared by reading")
                check_equal(client.gap(129) & 8, 8, "AP 129 bit 3: the deviation lasts")
                # The stop holds while the deviation persists; realigning AP 1 with the encoder ends it.
                client.ok(MVP, 0, 0, 3 * REV)
                client.wait_sim_ms(200)
                check_equal(client.gap(1), actual, "no motion while the deviation persists")
                client.ok(3)  # MST: no new move after the realignment
                client.sap(1, encoder)
                client.gap(207)  # clears the flag raised up to the realignment
                client.wait_sim_ms(100)  # ticks run between the replies
                check_equal(client.gap(129) & 8, 0, "deviation flag gone after AP 1 = AP 41")
                check_equal((client.gap(1), client.gap(207)), (encoder, 0), "at rest, no new deviation stop")
            server.stop()


def test_unusable_motor_is_a_start_up_error(motwin):
    with TempDir() as tmp:
        server = serve(motwin, tmp, "--motor", "default-24v")
        status = server.start_expect_failure()
        check_equal(status, 2, "exit status")
        check("tmcm-142: unknown stepper motor \"default-24v\"" in server.stderr_text(),
              f"stderr: {server.stderr_text()!r}")
        server.cleanup()


if __name__ == "__main__":
    run_tests([test_identity_io_and_can, test_ascii_homing_and_coordinates,
               test_blocked_rotor_stops_with_encoder_deviation, test_unusable_motor_is_a_start_up_error])
