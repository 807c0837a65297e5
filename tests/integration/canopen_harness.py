"""CAN helpers for the integration tests: `motwin serve --module tmcm-3216 --can socketcand:...`
and a raw-frame CANopen client on Debian's python3-can (socketcand interface).

Builds on motwin_harness (process handling, watchdog, run_tests); only the serve contract lines
and the client differ. Raw frames on purpose: what is checked is the wire, not a library's view.
"""

import re
import socket
import struct
import time

import motwin_harness as mh
from motwin_harness import ServerError, TestFailure, check, check_equal  # noqa: F401 - re-exported

NMT_START, NMT_STOP, NMT_PREOP, NMT_RESET_NODE, NMT_RESET_COMM = 0x01, 0x02, 0x80, 0x81, 0x82
STATE_BOOTUP, STATE_STOPPED, STATE_OPERATIONAL, STATE_PREOP = 0x00, 0x04, 0x05, 0x7F
SAVE = 0x65766173
LOAD = 0x64616F6C
SDO_TIMEOUT = 1.0


class CanServer(mh.Server):
    """`motwin serve` running a TMCM-3216 on a socketcand endpoint on a free port."""

    def __init__(self, motwin, state_dir, node_id=None, speed=None, extra_args=(),
                 can=("socketcand:127.0.0.1:0",)):
        super().__init__(motwin, state_dir, tcp=False)
        self.args = [motwin, "serve", "--module", "tmcm-3216", "--state-dir", state_dir]
        for spec in can:
            self.args += ["--can", spec]
        if node_id is not None:
            self.args += ["--node-id", str(node_id)]
        if speed:
            self.args += ["--speed", speed]
        self.args += list(extra_args)
        self.can_port = None
        self.slcan_port = None

    def _parse_line(self, text):
        if text == "ready":
            check(self.banner is not None, f"'ready' before the banner line: {self.stdout_lines!r}")
            check(self.can_port is not None or self.slcan_port is not None,
                  f"'ready' without a CAN endpoint: {self.stdout_lines!r}")
            return True
        m = re.fullmatch(r"motwin: tmcm-3216 \(CANopen V1\.04\) eeprom (.+)", text)
        if m:
            check(self.banner is None, f"two banner lines: {self.stdout_lines!r}")
            self.banner = text
            self.eeprom_path = m.group(1)
            return False
        m = re.fullmatch(r"endpoint can-socketcand 127\.0\.0\.1:(\d+)", text)
        if m:
            self.can_port = int(m.group(1))
            check(0 < self.can_port < 65536, f"bad port in {text!r}")
            return False
        m = re.fullmatch(r"endpoint can-slcan-tcp 127\.0\.0\.1:(\d+)", text)
        if m:
            self.slcan_port = int(m.group(1))
            check(0 < self.slcan_port < 65536, f"bad port in {text!r}")
            return False
        raise ServerError(f"unexpected line on serve's stdout: {text!r} (all: {self.stdout_lines!r})")

    def bus(self):
        return CanopenClient(self.can_port)

    def slcan_bus(self):
        return CanopenClient(self.slcan_port, interface="slcan")


class SdoAborted(TestFailure):
    def __init__(self, code, index, sub):
        super().__init__(f"SDO abort {code:08X} on {index:04X} sub {sub}")
        self.code = code


class CanopenClient:
    """python-can's socketcand Bus with CANopen master helpers speaking raw frames."""

    def __init__(self, port, interface="socketcand"):
        import can  # Debian's python3-can
        self.can = can
        if interface == "slcan":
            # A pyserial URL; python-can sleeps 2 s after opening a serial port unless told not to.
            self.bus = can.Bus(interface="slcan", channel=f"socket://127.0.0.1:{port}", bitrate=1000000,
                               sleep_after_open=0)
        else:
            self.bus = can.Bus(interface="socketcand", host="127.0.0.1", port=port, channel="can0")

    def close(self):
        self.bus.shutdown()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def send(self, cob_id, data):
        self.bus.send(self.can.Message(arbitration_id=cob_id, data=bytes(data), is_extended_id=False))

    def receive(self, predicate, timeout, what="frame"):
        """The first frame for which predicate(msg) is true; other frames are skipped."""
        deadline = time.monotonic() + timeout
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TestFailure(f"timed out after {timeout} s waiting for {what}")
            msg = self.bus.recv(remaining)
            if msg is not None and predicate(msg):
                return msg

    def collect(self, duration, predicate=lambda msg: True):
        """Every frame matching predicate within `duration` seconds (wall time)."""
        frames = []
        deadline = time.monotonic() + duration
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return frames
            msg = self.bus.recv(remaining)
            if msg is not None and predicate(msg):
                frames.append(msg)

    def drain(self, duration=0.05):
        self.collect(duration)

    # NMT ------------------------------------------------------------------------------------------
    def nmt(self, command, node):
        self.send(0x000, [command, node])

    def wait_state(self, node, state, timeout=2.0):
        return self.receive(lambda m: m.arbitration_id == 0x700 + node and len(m.data) == 1 and m.data[0] == state,
                            timeout, f"state {state:#04x} from node {node}")

    # SDO ------------------------------------------------------------------------------------------
    def _request(self, node, data, timeout=SDO_TIMEOUT):
        self.send(0x600 + node, data)
        return self.receive(lambda m: m.arbitration_id == 0x580 + node, timeout, f"SDO response of node {node}")

    @staticmethod
    def _check_abort(response, index, sub):
        data = bytes(response.data)
        check_equal(len(data), 8, "SDO response length")
        if data[0] == 0x80:
            code = struct.unpack_from("<I", data, 4)[0]
            check_equal(struct.unpack_from("<HB", data, 1), (index, sub), "abort multiplexer")
            raise SdoAborted(code, index, sub)
        return data

    def upload(self, node, index, sub):
        data = self._check_abort(self._request(node, [0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0]), index, sub)
        check_equal(struct.unpack_from("<HB", data, 1), (index, sub), "upload response multiplexer")
        if data[0] & 0x02:  # expedited
            n = 4 - ((data[0] >> 2) & 3) if data[0] & 0x01 else 4
            return data[4:4 + n]
        check_equal(data[0], 0x41, "initiate upload response")
        size = struct.unpack_from("<I", data, 4)[0]
        value = b""
        toggle = 0
        while True:
            seg = self._check_abort(self._request(node, [0x60 | toggle, 0, 0, 0, 0, 0, 0, 0]), index, sub)
            check_equal(seg[0] & 0x10, toggle, "upload segment toggle")
            value += seg[1:8 - ((seg[0] >> 1) & 7)]
            if seg[0] & 0x01:
                break
            toggle ^= 0x10
        check_equal(len(value), size, "segmented upload size")
        return value

    def upload_u(self, node, index, sub):
        return int.from_bytes(self.upload(node, index, sub), "little")

    def download(self, node, index, sub, value, size):
        payload = value.to_bytes(size, "little") if isinstance(value, int) else bytes(value)
        check(len(payload) <= 4, "expedited download only")
        header = 0x23 | ((4 - len(payload)) << 2)
        data = self._check_abort(
            self._request(node, [header, index & 0xFF, index >> 8, sub] + list(payload.ljust(4, b"\0"))), index, sub)
        check_equal(data[0], 0x60, "initiate download response")

    def abort_code(self, operation, *args):
        try:
            operation(*args)
        except SdoAborted as aborted:
            return aborted.code
        raise TestFailure(f"{operation.__name__}{args} was not aborted")


class RawSocketcand:
    """A plain TCP socket speaking the socketcand protocol by hand (for garbage tests)."""

    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.buffer = b""

    def send(self, text):
        self.sock.sendall(text.encode("ascii") if isinstance(text, str) else text)

    def read_element(self, timeout=2.0):
        deadline = time.monotonic() + timeout
        while True:
            start = self.buffer.find(b"<")
            end = self.buffer.find(b">", start + 1) if start >= 0 else -1
            if start >= 0 and end >= 0:
                element = self.buffer[start:end + 1].decode("ascii")
                self.buffer = self.buffer[end + 1:]
                return element
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TestFailure(f"no socketcand element within {timeout} s (have {self.buffer!r})")
            self.sock.settimeout(remaining)
            try:
                chunk = self.sock.recv(4096)
            except socket.timeout:
                continue
            if not chunk:
                raise TestFailure("socketcand server closed the connection")
            self.buffer += chunk

    def close(self):
        self.sock.close()
