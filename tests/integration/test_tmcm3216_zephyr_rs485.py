#!/usr/bin/python3
"""Zephyr's TMCM-3216 driver (zephyrproject-rtos/zephyr drivers/stepper/adi_tmc/tmcm3216/ on the
RS485 bus driver drivers/stepper/adi_tmc/bus/adi_tmcm_rs485.c) replayed over a pseudo-terminal
against `motwin serve --module tmcm-3216 --firmware tmcl --tmcl-pty LINK,echo`.

The bus driver talks to module address 1 (the devicetree's `reg`) through an RS485 transceiver
that hands every transmitted byte back: it flushes its receiver, writes one byte and waits (100 ms
at most) for that byte to come back before it writes the next; after the ninth echo it reads the
9-byte reply (1000 ms per byte) and accepts only a correct checksum and status 100. The client
below speaks the same way through pyserial, but its waits are liveness bounds (REPLY_TIMEOUT), not
the driver's: the machine running the tests may be loaded. It reports the slowest echo it saw.

The sequence is the driver's: the stepper driver's init (SAP 140 = log2(16)), the controller's
(SAP 4 = 2000, SAP 5 = 500), enable (SAP 6 = 100), the vendor calls setting max velocity and
acceleration, set_reference_position (SAP 1), move_by (MVP REL) and move_to (MVP ABS) each followed
by is_moving polls every 100 ms (GAP 8, then GAP 3; moving while AP 8 == 0 and AP 3 != 0),
tmcm3216_get_status (GAP 1, 3, 8, 10, 11), run (GAP 4, then ROR or ROL at that velocity), stop
(MST), disable (MST, SAP 6 = 0, SAP 7 = 0). A right stop switch at position 8000
(`--set AXIS0_REF_R_AT=2.5`) stops the positive run; AP 10 says so.

Without `,echo` the same link gives no echo: a frame's reply is the first 9 bytes read.
"""

import os
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from motwin_harness import (  # noqa: E402
    BANK_GLOBAL, GAP, GGP, HOST_ADDRESS, MODULE_ADDRESS, MST, MVP, MVP_ABS, MVP_REL, REPLY_TIMEOUT, ROL, ROR, SAP,
    STATUS_OK, Server, Skipped, TempDir, TestFailure, check, check_equal, checksum, frame, run_tests,
)

# Zephyr's tmcm3216_reg.h names for the axis parameters the driver uses.
TARGET_POSITION, ACTUAL_POSITION, ACTUAL_VELOCITY, MAX_VELOCITY, MAX_ACCELERATION = 0, 1, 3, 4, 5
MAX_CURRENT, STANDBY_CURRENT, POSITION_REACHED, RIGHT_ENDSTOP, LEFT_ENDSTOP = 6, 7, 8, 10, 11
MICROSTEP_RESOLUTION = 140
MICROSTEPS = 16                      # the devicetree's micro-step-res (the binding's default)
# The right stop switch, in AP 1 units: far enough out that the positive run spends seconds at full
# speed before it gets there, so the status polls see that speed however slowly a loaded machine
# answers them. At AP 140 = 4 the rotor turns once per 3200 of AP 1 (--set takes revolutions).
RIGHT_SWITCH_AT = 8000
ROTOR_MICROSTEPS_PER_REVOLUTION = 200 * MICROSTEPS
POLL_INTERVAL_S = 0.1                # TMCM3216_POLL_INTERVAL_MS: the driver's rhythm, not a bound
POLL_BUDGET_MS = 60000               # simulated time a move or a run may take before the test gives up
TICK_TIMER = 132                     # GP, simulated milliseconds
DRIVER_ECHO_TIMEOUT_S = 0.1          # what the driver allows per echo (reported, not asserted)


def signed32(value):
    return value - (1 << 32) if value & 0x80000000 else value


def open_serial(link):
    try:
        import serial  # Debian's python3-serial: a third-party peer on the pty
    except ImportError:
        raise Skipped("python3-serial (pyserial) is not installed")
    return serial.Serial(link, 9600, timeout=0)  # the Zephyr sample's current-speed; a pty ignores it


def read_byte(port, what):
    """One byte, waiting as long as a loaded machine may need (a liveness bound)."""
    deadline = time.monotonic() + REPLY_TIMEOUT
    while True:
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            raise TestFailure(f"no {what} within {REPLY_TIMEOUT} s")
        port.timeout = min(remaining, 1.0)
        byte = port.read(1)
        if byte:
            return byte[0]


class ZephyrRs485Bus:
    """tmcm_rs485_send_command() as Zephyr's bus driver does it, byte by byte with its echo."""

    def __init__(self, port):
        self.port = port
        self.slowest_echo_s = 0.0
        self.commands = 0

    def send_command(self, command, type_, motor, value):
        """The reply's value (signed), after checking the echo of every byte, the reply's checksum,
        status 100 exactly, the module address and the command."""
        request = frame(command, type_, motor, value, MODULE_ADDRESS)
        what = f"command {command} type {type_} motor {motor} value {value}"
        # Flush stale input: read until nothing is there, as uart_poll_in() in a loop.
        self.port.timeout = 0
        stale = self.port.read(4096)
        check(stale == b"", f"{what}: {len(stale)} stale bytes before the request: {stale.hex(' ')}")
        for index, byte in enumerate(request):
            sent_at = time.monotonic()
            self.port.write(bytes([byte]))
            self.port.flush()
            echo = read_byte(self.port, f"echo of byte {index} of {what}")
            self.slowest_echo_s = max(self.slowest_echo_s, time.monotonic() - sent_at)
            check(echo == byte, f"{what}: echo of byte {index} is 0x{echo:02x}, sent 0x{byte:02x}")
        reply = bytes(read_byte(self.port, f"reply byte {index} of {what}") for index in range(9))
        check_equal(reply[8], checksum(reply[:8]), f"{what}: reply checksum ({reply.hex(' ')})")
        check_equal(reply[2], STATUS_OK, f"{what}: reply status ({reply.hex(' ')})")
        check_equal(reply[0], HOST_ADDRESS, f"{what}: reply host address")
        check_equal(reply[1], MODULE_ADDRESS, f"{what}: reply module address (the devicetree's reg)")
        check_equal(reply[3], command, f"{what}: reply command")
        self.commands += 1
        return signed32(int.from_bytes(reply[4:8], "big"))


class Tmcm3216Stepper:
    """Motor 0 as Zephyr's adi,tmcm3216-stepper-driver and -stepper-ctrl drive it."""

    def __init__(self, bus, motor=0):
        self.bus = bus
        self.motor = motor

    def sap(self, number, value):
        return self.bus.send_command(SAP, number, self.motor, value)

    def gap(self, number):
        return self.bus.send_command(GAP, number, self.motor, 0)

    def sim_ms(self):
        return self.bus.send_command(GGP, TICK_TIMER, BANK_GLOBAL, 0)

    # stepper driver / stepper ctrl
    def init(self):
        self.sap(MICROSTEP_RESOLUTION, MICROSTEPS.bit_length() - 1)  # log2(16) = 4
        self.sap(MAX_VELOCITY, 2000)
        self.sap(MAX_ACCELERATION, 500)

    def enable(self):
        self.sap(MAX_CURRENT, 100)

    def disable(self):
        self.bus.send_command(MST, 0, self.motor, 0)
        self.sap(MAX_CURRENT, 0)
        self.sap(STANDBY_CURRENT, 0)

    def is_moving(self):
        position_reached = self.gap(POSITION_REACHED)
        velocity = self.gap(ACTUAL_VELOCITY)
        return position_reached == 0 and velocity != 0

    def status(self):
        """tmcm3216_get_status()."""
        position = self.gap(ACTUAL_POSITION)
        velocity = self.gap(ACTUAL_VELOCITY)
        return {"position": position, "velocity": velocity, "moving": velocity != 0,
                "position_reached": self.gap(POSITION_REACHED) != 0,
                "right_endstop": self.gap(RIGHT_ENDSTOP) != 0, "left_endstop": self.gap(LEFT_ENDSTOP) != 0}

    def wait_until_not_moving(self, what):
        """The driver's poll work: is_moving every 100 ms until false (STEPS_COMPLETED). Bounded by
        simulated time (GP 132, read every ten polls), so a loaded machine only makes it slower.
        Whether the first poll still sees the move depends on the machine's speed: not asserted."""
        deadline_ms = self.sim_ms() + POLL_BUDGET_MS
        polls = 0
        while True:
            time.sleep(POLL_INTERVAL_S)
            if not self.is_moving():
                return
            polls += 1
            if polls % 10 == 0 and self.sim_ms() > deadline_ms:
                raise TestFailure(f"{what}: still moving after {POLL_BUDGET_MS} ms (simulated): {self.status()}")

    def poll_status_until(self, what, predicate):
        deadline_ms = self.sim_ms() + POLL_BUDGET_MS
        while True:
            status = self.status()
            if predicate(status):
                return status
            if self.sim_ms() > deadline_ms:
                raise TestFailure(f"{what}: not within {POLL_BUDGET_MS} ms (simulated); last {status}")
            time.sleep(POLL_INTERVAL_S)

    def move(self, mvp_type, value, target, what):
        self.bus.send_command(MVP, mvp_type, self.motor, value)
        check_equal(self.gap(TARGET_POSITION), target, f"{what}: AP 0")
        self.wait_until_not_moving(what)
        status = self.status()
        check_equal(status["position"], target, f"{what}: AP 1 once the driver sees the move done")
        check(status["position_reached"] and status["velocity"] == 0, f"{what}: at rest on the target: {status}")

    def run(self, command):
        velocity = self.gap(MAX_VELOCITY)
        self.bus.send_command(command, 0, self.motor, velocity)
        return velocity


class Tmcm3216TmclPtyServer(Server):
    """`motwin serve --module tmcm-3216 --firmware tmcl --tmcl-pty LINK[,echo] --state-dir none`."""

    BANNER = r"motwin: tmcm-3216 \(3216V100\) eeprom (.+)"

    def __init__(self, motwin, link, echo, extra_args=()):
        super().__init__(motwin, "none", tcp=False, pty_link=link + (",echo" if echo else ""), module="tmcm-3216",
                         extra_args=["--firmware", "tmcl"] + list(extra_args))


def test_zephyr_driver_sequence_with_the_rs485_echo(motwin):
    """Init, enable, MVP REL 3200 and MVP ABS 1600 polled to completion, the status, a positive run
    into the right switch, a negative run stopped with MST, disable: every byte echoed before the
    next was sent, every reply 9 bytes with status 100, a right checksum and module address 1."""
    with TempDir() as tmp:
        link = os.path.join(tmp, "tmcm3216")
        switch = ["--set", f"AXIS0_REF_R_AT={RIGHT_SWITCH_AT / ROTOR_MICROSTEPS_PER_REVOLUTION}"]
        with Tmcm3216TmclPtyServer(motwin, link, echo=True, extra_args=switch) as server:
            check(server.pty_echo, "the endpoint line says echo")
            check_equal(server.pty_link, link, "the link's name, without the option")
            port = open_serial(link)
            try:
                bus = ZephyrRs485Bus(port)
                stepper = Tmcm3216Stepper(bus)
                stepper.init()
                check_equal(stepper.gap(MICROSTEP_RESOLUTION), 4, "AP 140 (get_micro_step_res: 16)")
                stepper.enable()
                # The sample's vendor calls: tmcm3216_set_max_velocity / _set_max_acceleration.
                stepper.sap(MAX_ACCELERATION, 4000)
                check_equal(stepper.gap(MAX_VELOCITY), 2000, "AP 4 (tmcm3216_get_max_velocity)")
                stepper.sap(ACTUAL_POSITION, 0)  # set_reference_position(0)

                stepper.move(MVP_REL, 3200, 3200, "move_by(3200)")
                status = stepper.status()
                check(not status["right_endstop"] and not status["left_endstop"], f"no switch at 1 rev: {status}")
                stepper.move(MVP_ABS, 1600, 1600, "move_to(1600)")

                # run(positive) into the right switch: the switch stops it.
                check_equal(stepper.run(ROR), 2000, "run(positive): ROR at AP 4")
                stepper.poll_status_until("ROR: the axis at 2000 pps", lambda s: s["velocity"] == 2000)
                status = stepper.poll_status_until("ROR: the right switch stops the axis",
                                                   lambda s: s["right_endstop"] and s["velocity"] == 0)
                check(abs(status["position"] - RIGHT_SWITCH_AT) <= 40,
                      f"AP 1 {status['position']} at the switch, at {RIGHT_SWITCH_AT}")
                check(not stepper.is_moving(), "is_moving() at the switch")
                bus.send_command(MST, 0, 0, 0)  # stop()

                # run(negative) away from it, then stop(): the ramp brings the axis to rest.
                check_equal(stepper.run(ROL), 2000, "run(negative): ROL at AP 4")
                stepper.poll_status_until("ROL: the axis at -2000 pps, off the switch",
                                          lambda s: s["velocity"] == -2000 and not s["right_endstop"])
                bus.send_command(MST, 0, 0, 0)
                status = stepper.poll_status_until("MST: the axis at rest", lambda s: s["velocity"] == 0)
                check(status["position"] < RIGHT_SWITCH_AT and not status["left_endstop"],
                      f"after ROL and MST: {status}")
                check(not stepper.is_moving(), "is_moving() after MST")
                stepper.disable()
                check_equal([stepper.gap(MAX_CURRENT), stepper.gap(STANDBY_CURRENT)], [0, 0], "AP 6, 7 after disable")
                print(f"     {bus.commands} commands, slowest echo {bus.slowest_echo_s * 1000:.1f} ms "
                      f"(the driver allows {DRIVER_ECHO_TIMEOUT_S * 1000:.0f} ms)", flush=True)
            finally:
                port.close()
            server.stop()


def test_without_the_option_no_echo_comes(motwin):
    """The same serve without `,echo`: the first 9 bytes after a frame are its reply, and nothing
    follows them."""
    with TempDir() as tmp:
        link = os.path.join(tmp, "tmcm3216")
        with Tmcm3216TmclPtyServer(motwin, link, echo=False) as server:
            check(not server.pty_echo, "the endpoint line says no echo")
            port = open_serial(link)
            try:
                request = frame(GAP, MAX_VELOCITY, 0, 0, MODULE_ADDRESS)
                port.write(request)
                port.flush()
                reply = bytes(read_byte(port, f"reply byte {index}") for index in range(9))
                check(reply != request, f"the first 9 bytes are the request again: {reply.hex(' ')}")
                check_equal(reply[:4], bytes([HOST_ADDRESS, MODULE_ADDRESS, STATUS_OK, GAP]), "reply header")
                check_equal(reply[8], checksum(reply[:8]), "reply checksum")
                port.timeout = 0.3  # an absence: nothing more than the reply comes
                check_equal(port.read(64), b"", "bytes after the reply")
            finally:
                port.close()
            server.stop()


if __name__ == "__main__":
    run_tests([test_zephyr_driver_sequence_with_the_rs485_echo, test_without_the_option_no_echo_comes])
