"""Helpers for the bus tests (test_can_*.py, test_tmcl_can*.py, test_lss_*.py): a `motwin serve`
whose every stdout line is parsed (one or several modules, every kind of CAN endpoint), a TMCL
over CAN client on Debian's python3-can, and a free-port finder. Its python-can helpers (open_bus,
receive, collect) serve canopen_harness's CANopen client too.

Builds on motwin_harness (process handling, watchdog, run_tests).
"""

import logging
import re
import socket
import struct
import time

import motwin_harness as mh
from motwin_harness import ServerError, TestFailure, check, check_equal  # noqa: F401 - re-exported

TMCL_RECEIVE_ID, TMCL_SEND_ID = 1, 2
STATUS_OK = 100

# python-can's socketcand reader warns each time a TCP read ends inside a frame, which a busy
# stream does all the time, and then simply reads on: the warnings only drowned the test output.
logging.getLogger("can.interfaces.socketcand").setLevel(logging.ERROR)


class BusServer(mh.Server):
    """`motwin serve ARGS...` with any module(s) and CAN endpoints; `args` follow "serve"."""

    def __init__(self, motwin, state_dir, args):
        super().__init__(motwin, state_dir, tcp=False)
        self.args = [motwin, "serve", "--state-dir", state_dir] + list(args)
        self.banners = []        # (name or None, module, firmware, eeprom)
        self.endpoints = {}      # kind -> list of the rest of the line, split
        self.stats_lines = []

    def _parse_line(self, text):
        if text == "ready":
            check(self.banners, f"'ready' before the banner line: {self.stdout_lines!r}")
            return True
        m = re.fullmatch(r"motwin: node (\S+) (\S+) \((.*)\) eeprom (.+)", text)
        if m:
            self.banners.append((m.group(1), m.group(2), m.group(3), m.group(4)))
            self.banner = text
            return False
        m = re.fullmatch(r"motwin: (\S+) \((.*)\) eeprom (.+)", text)
        if m:
            self.banners.append((None, m.group(1), m.group(2), m.group(3)))
            self.banner = text
            return False
        m = re.fullmatch(r"endpoint (\S+) (.+)", text)
        if m:
            self.endpoints.setdefault(m.group(1), []).append(m.group(2).split())
            return False
        raise ServerError(f"unexpected line on serve's stdout: {text!r} (all: {self.stdout_lines!r})")

    def port(self, kind="can-socketcand", index=0):
        return int(self.endpoints[kind][index][0].rsplit(":", 1)[1])

    def tcp_port_of(self, kind="tmcl-tcp"):
        return self.port(kind)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def open_bus(port, interface="socketcand", channel=None):
    """A python-can bus on a socketcand or SLCAN-over-TCP endpoint of 127.0.0.1:`port`."""
    import can  # Debian's python3-can
    if interface == "slcan":
        # A pyserial URL; python-can sleeps 2 s after opening a serial port unless told not to.
        return can.Bus(interface="slcan", channel=channel or f"socket://127.0.0.1:{port}", bitrate=1000000,
                       sleep_after_open=0)
    return can.Bus(interface="socketcand", host="127.0.0.1", port=port, channel="can0")


def receive(bus, predicate, timeout, what="frame"):
    """The first frame for which predicate(msg) is true; other frames are skipped."""
    deadline = time.monotonic() + timeout
    while True:
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            raise TestFailure(f"timed out after {timeout} s waiting for {what}")
        msg = bus.recv(remaining)
        if msg is not None and predicate(msg):
            return msg


def collect(bus, duration, predicate=lambda msg: True):
    """Every frame matching predicate within `duration` seconds (wall time)."""
    frames = []
    deadline = time.monotonic() + duration
    while True:
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            return frames
        msg = bus.recv(remaining)
        if msg is not None and predicate(msg):
            frames.append(msg)


def collect_through(bus, predicate, last, linger=0.3, timeout=mh.FRAME_TIMEOUT):
    """collect() for "exactly these frames": every frame matching predicate until one matching
    `last` (the answer a test waits for, however late a loaded machine brings it) and `linger`
    seconds after it (anything more that comes)."""
    frames = []
    deadline = time.monotonic() + timeout
    while not frames or not last(frames[-1]):
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            raise TestFailure(f"timed out after {timeout} s; frames so far {frames!r}")
        msg = bus.recv(remaining)
        if msg is not None and predicate(msg):
            frames.append(msg)
    return frames + collect(bus, linger, predicate)


class TmclCan:
    """TMCL over CAN on a python-can bus: requests on `receive_id`, replies on `send_id`."""

    def __init__(self, bus, receive_id=TMCL_RECEIVE_ID, send_id=TMCL_SEND_ID, length=7):
        import can
        self.can = can
        self.bus = bus
        self.receive_id = receive_id
        self.send_id = send_id
        self.length = length

    def send_raw(self, data, can_id=None):
        self.bus.send(self.can.Message(arbitration_id=self.receive_id if can_id is None else can_id,
                                       data=bytes(data), is_extended_id=False))

    def request_raw(self, data, timeout=mh.FRAME_TIMEOUT):
        self.send_raw(data)
        return bytes(receive(self.bus, lambda m: m.arbitration_id == self.send_id, timeout,
                             f"TMCL reply on ID {self.send_id}").data)

    def request(self, command, type_=0, motor=0, value=0, length=None):
        length = length or self.length
        data = struct.pack(">BBBi", command, type_, motor, value)
        if length == 8:
            data += bytes([(self.receive_id + sum(data)) & 0xFF])
        return self.request_raw(data)

    def ok(self, command, type_=0, motor=0, value=0, length=None):
        reply = self.request(command, type_, motor, value, length)
        check_equal(reply[1], STATUS_OK, f"status of command {command} type {type_}")
        return struct.unpack_from(">i", reply, 3)[0]
