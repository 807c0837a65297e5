"""Shared helpers for the integration tests: start `motwin serve`, talk TMCL to it, stop it.

Standard library only (pyserial is imported lazily by SerialClient). Every test script is run by
CTest as `/usr/bin/python3 <script> --motwin <path to build/motwin>`; exit status 0 means pass.

Conventions
- Servers listen on 127.0.0.1 port 0 and/or a pseudo-terminal whose link lives in a temporary
  directory; the ports and devices are taken from the `endpoint` lines of `motwin serve`.
- A server is started with PR_SET_PDEATHSIG, so it dies with the thread that started it even if
  the test is killed: start servers from the main thread only.
- Every wait has a timeout; `run_tests` also arms a watchdog for the whole script.
"""

import argparse
import collections
import ctypes
import fcntl
import os
import re
import selectors
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import termios
import threading
import time
import traceback
import zlib

MODULE_ADDRESS = 1
HOST_ADDRESS = 2
FRAME_LENGTH = 9

# Command numbers (TMCM-1636 manual table 4; docs/tmcl-protocol.md "Control commands").
ROR, ROL, MST, MVP, SAP, GAP, STAP, RSAP, SGP, GGP, STGP, RSGP = 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12
GET_VERSION = 136
FACTORY_DEFAULTS = 137
SOFTWARE_RESET = 255
RESET_MAGIC = 1234
MVP_ABS, MVP_REL = 0, 1
BANK_GLOBAL, BANK_USER = 0, 2

STATUS_OK = 100
STATUS_CHECKSUM = 1
STATUS_INVALID_COMMAND = 2
STATUS_WRONG_TYPE = 3
STATUS_INVALID_VALUE = 4

VERSION_STRING = b"1636V109"
VERSION_BINARY = 0x06640109

# Factory defaults (parameter table of src/core/modules/tmcm1636/tmcm1636_parameters.cpp).
DEFAULT_MAX_VELOCITY = 4000      # AP 43
DEFAULT_ACCELERATION = 2000      # AP 44
DEFAULT_REACHED_DISTANCE = 5     # AP 53
DEFAULT_REACHED_VELOCITY = 500   # AP 54
DEFAULT_ADC_OFFSET = 32767       # AP 5, 6
DEFAULT_AUTO_START = 1           # GP 77

# Liveness bounds, not timing requirements: the same scripts run against an ASan+UBSan build on a
# machine whose cores other jobs keep busy, where a reply that takes 0.2 ms idle can take seconds.
# A test that asserts an absence (expect_no_reply, read_available) says how long it waits.
STARTUP_TIMEOUT = 30.0
REPLY_TIMEOUT = 10.0
FRAME_TIMEOUT = 10.0  # a CAN frame the test waits for (an EMCY, a TPDO, a reply)
STOP_TIMEOUT = 15.0


class TestFailure(AssertionError):
    pass


# The exit status of a script whose every test was skipped: CTest reports it as skipped
# (SKIP_RETURN_CODE in tests/CMakeLists.txt), not as passed.
SKIP_STATUS = 77


class Skipped(Exception):
    """Raised by a test that cannot run here (a tool missing, a build it does not apply to):
    run_tests reports `skip NAME: reason` instead of a failure."""


def check(condition, message):
    if not condition:
        raise TestFailure(message)


def check_equal(actual, expected, what):
    if actual != expected:
        raise TestFailure(f"{what}: expected {expected!r}, got {actual!r}")


# --- Frames -----------------------------------------------------------------------------------

def checksum(data):
    return sum(data) & 0xFF


def frame(command, type_=0, motor=0, value=0, address=MODULE_ADDRESS):
    """A 9-byte TMCL request: addr cmd type motor value(4, big-endian) checksum."""
    body = struct.pack(">BBBBI", address & 0xFF, command & 0xFF, type_ & 0xFF, motor & 0xFF, value & 0xFFFFFFFF)
    return body + bytes([checksum(body)])


Reply = collections.namedtuple("Reply", "host module status command value raw")


def parse_reply(raw):
    check(len(raw) == FRAME_LENGTH, f"reply has {len(raw)} bytes, not 9: {raw.hex(' ')}")
    check(checksum(raw[:8]) == raw[8], f"reply checksum wrong: {raw.hex(' ')}")
    host, module, status, command, value = struct.unpack(">BBBBi", raw[:8])
    return Reply(host, module, status, command, value, raw)


def expect_reply(reply, command, status=STATUS_OK, value=None, what=""):
    """Checks the addresses, status, echoed command and (optionally) the value of a reply."""
    label = what or f"reply to command {command}"
    check_equal(reply.host, HOST_ADDRESS, f"{label}: host address")
    check_equal(reply.module, MODULE_ADDRESS, f"{label}: module address")
    check_equal(reply.status, status, f"{label}: status ({reply.raw.hex(' ')})")
    check_equal(reply.command, command, f"{label}: command")
    if value is not None:
        check_equal(reply.value, value, f"{label}: value")
    return reply


# --- Clients ----------------------------------------------------------------------------------

class ClientBase:
    """request() sends one frame and reads its 9-byte reply; helpers assert status 100."""

    LINK = "link"  # names the link in failures: "TCP", "pty"

    def send_raw(self, data):
        raise NotImplementedError

    def read_some(self, n, timeout):
        """Up to `n` bytes, those that arrive within `timeout` seconds (b"" if none); None when the
        server closed the link."""
        raise NotImplementedError

    def close(self):
        raise NotImplementedError

    def read_exact(self, n, timeout=REPLY_TIMEOUT):
        deadline = time.monotonic() + timeout
        data = b""
        while len(data) < n:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TestFailure(f"{self.LINK}: timed out after {timeout} s with {len(data)} of {n} bytes: "
                                  f"{data.hex(' ')}")
            chunk = self.read_some(n - len(data), remaining)
            if chunk is None:
                raise TestFailure(f"{self.LINK}: connection closed by the server after {len(data)} of {n} bytes")
            data += chunk
        return data

    def read_available(self, timeout):
        """Whatever arrives within `timeout` seconds (b"" if nothing)."""
        raise NotImplementedError

    def request_raw(self, data, timeout=REPLY_TIMEOUT):
        self.send_raw(data)
        return self.read_exact(FRAME_LENGTH, timeout)

    def request(self, command, type_=0, motor=0, value=0, address=MODULE_ADDRESS, timeout=REPLY_TIMEOUT):
        return parse_reply(self.request_raw(frame(command, type_, motor, value, address), timeout))

    def expect_no_reply(self, timeout=0.3, what="frame"):
        data = self.read_available(timeout)
        check(data == b"", f"{what}: expected no reply, got {data.hex(' ')}")

    # Assertive shortcuts: every reply checked.
    def ok(self, command, type_=0, motor=0, value=0, what=""):
        return expect_reply(self.request(command, type_, motor, value), command, STATUS_OK,
                            what=what or f"command {command} type {type_} motor {motor} value {value}")

    def sap(self, number, value, motor=0):
        return expect_reply(self.request(SAP, number, motor, value), SAP, STATUS_OK, value,
                            what=f"SAP {number}, {motor}, {value}")

    def gap(self, number, motor=0):
        return expect_reply(self.request(GAP, number, motor), GAP, STATUS_OK, what=f"GAP {number}, {motor}").value

    def stap(self, number, motor=0):
        return expect_reply(self.request(STAP, number, motor), STAP, STATUS_OK, what=f"STAP {number}, {motor}")

    def rsap(self, number, motor=0):
        return expect_reply(self.request(RSAP, number, motor), RSAP, STATUS_OK, what=f"RSAP {number}, {motor}")

    def sgp(self, number, bank, value):
        return expect_reply(self.request(SGP, number, bank, value), SGP, STATUS_OK, value,
                            what=f"SGP {number}, {bank}, {value}")

    def ggp(self, number, bank):
        return expect_reply(self.request(GGP, number, bank), GGP, STATUS_OK, what=f"GGP {number}, {bank}").value

    def stgp(self, number, bank):
        return expect_reply(self.request(STGP, number, bank), STGP, STATUS_OK, what=f"STGP {number}, {bank}")

    def rsgp(self, number, bank):
        return expect_reply(self.request(RSGP, number, bank), RSGP, STATUS_OK, what=f"RSGP {number}, {bank}")

    def version_string(self):
        raw = self.request_raw(frame(GET_VERSION, 0))
        check_equal(raw[0], HOST_ADDRESS, "136 type 0: host address")
        return bytes(raw[1:])

    def wait_sim_ms(self, milliseconds):
        """Waits until the module's own clock, GP 132 (the TMCL tick timer, milliseconds of
        simulated time), has advanced by `milliseconds`: what time.sleep() means when the host
        keeps up with the wall clock, which a loaded machine does not."""
        start_ms = last_ms = self.ggp(132, BANK_GLOBAL)
        last_progress = time.monotonic()
        while last_ms < start_ms + milliseconds:
            time.sleep(0.002)
            now_ms = self.ggp(132, BANK_GLOBAL)
            if now_ms != last_ms:
                last_ms, last_progress = now_ms, time.monotonic()
            elif time.monotonic() - last_progress > 60.0:
                raise TestFailure(f"GP 132 (tick timer) stood still at {now_ms} ms for 60 s")

    def wait_for(self, description, predicate, timeout, interval=0.005):
        """Polls predicate() (which talks to the module) until true; returns its last value."""
        return poll_until(description, predicate, timeout, interval)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class TcpClient(ClientBase):
    LINK = "TCP"

    def __init__(self, port, host="127.0.0.1", timeout=5.0):
        self.sock = socket.create_connection((host, port), timeout=timeout)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    @classmethod
    def from_socket(cls, sock):
        client = cls.__new__(cls)
        client.sock = sock
        return client

    def send_raw(self, data):
        self.sock.settimeout(REPLY_TIMEOUT)
        self.sock.sendall(data)

    def read_some(self, n, timeout):
        self.sock.settimeout(timeout)
        try:
            return self.sock.recv(n) or None
        except socket.timeout:
            return b""

    def read_available(self, timeout):
        self.sock.settimeout(timeout)
        try:
            data = self.sock.recv(4096)
        except socket.timeout:
            return b""
        return data if data else b""

    def wait_until_server_read_everything(self, timeout=60.0):
        """Waits until the server has read every byte this client sent: nothing left in this
        socket's send queue nor in the server's receive queue (/proc/net/tcp). A loaded server
        (a sanitizer build, busy cores) may still be working through a burst long after the
        client sent it; a pause meant for the server (the resync gap) only starts then."""
        wait_until_read_by_peer(self.sock, timeout)

    def close(self):
        try:
            self.sock.close()
        except OSError:
            pass


def _unsent_bytes(sock):
    """Bytes in the socket's send queue not yet acknowledged by the peer's kernel (SIOCOUTQ)."""
    return struct.unpack("i", fcntl.ioctl(sock.fileno(), termios.TIOCOUTQ, b"\0" * 4))[0]


def _proc_net_address(address):
    """("127.0.0.1", 5000) as /proc/net/tcp writes it: 0100007F:1388."""
    host, port = address[:2]
    return f"{struct.unpack('<I', socket.inet_aton(host))[0]:08X}:{port:04X}"


def _peer_receive_queue(sock):
    """Bytes the peer process has not read yet from the connection of `sock` (both ends on this
    host, IPv4): the rx_queue of the peer's socket in /proc/net/tcp; None if it is not listed."""
    peer_local = _proc_net_address(sock.getpeername())
    peer_remote = _proc_net_address(sock.getsockname())
    with open("/proc/net/tcp") as f:
        next(f)
        for line in f:
            fields = line.split()
            if fields[1] == peer_local and fields[2] == peer_remote:
                return int(fields[4].split(":")[1], 16)
    return None


def bytes_received_at(port):
    """For each established connection of the server listening on 127.0.0.1:`port`: how many
    bytes its client has sent that the server has read (tcp_info's bytes_received less Recv-Q,
    from iproute2's ss)."""
    out = subprocess.run(["ss", "-tinH", "state", "established", f"( sport = :{port} )"], capture_output=True,
                         text=True, timeout=30, check=True).stdout.split("\n")
    received = []
    for head, info in zip(out[0::2], out[1::2]):
        m = re.search(r"\bbytes_received:(\d+)", info)
        received.append((int(m.group(1)) if m else 0) - int(head.split()[0]))
    return received


def poll_until(description, predicate, timeout, interval=0.005):
    """Polls predicate() (which talks to the module) until true and returns its value; `timeout`
    (wall seconds) only bounds a module that stopped answering or a simulation that stood still."""
    deadline = time.monotonic() + timeout
    while True:
        result = predicate()
        if result:
            return result
        if time.monotonic() > deadline:
            raise TestFailure(f"timed out after {timeout} s waiting for {description}")
        time.sleep(interval)


def wait_until_read_by_peer(sock, timeout=60.0):
    """Waits until the other end (a server on this host) has read everything sent on `sock`."""
    deadline = time.monotonic() + timeout
    while True:
        unsent, unread = _unsent_bytes(sock), _peer_receive_queue(sock)
        if unsent == 0 and not unread:
            return
        if time.monotonic() > deadline:
            raise TestFailure(f"the server has not read what it was sent after {timeout} s: {unsent} bytes "
                              f"still to send, {unread} unread in its receive queue")
        time.sleep(0.01)


class SerialClient(ClientBase):
    """pyserial on the server's pseudo-terminal link, as a host application would open it."""

    LINK = "pty"

    def __init__(self, link, baudrate=115200):
        import serial  # Debian's python3-serial
        self.port = serial.Serial(link, baudrate, timeout=1)
        self.port.reset_input_buffer()

    def send_raw(self, data):
        self.port.write(data)
        self.port.flush()

    def read_some(self, n, timeout):
        self.port.timeout = min(timeout, 1.0)
        return self.port.read(n)

    def read_available(self, timeout):
        self.port.timeout = timeout
        data = self.port.read(4096)
        self.port.timeout = 1
        return data

    def close(self):
        try:
            self.port.close()
        except Exception:  # noqa: BLE001 - closing only
            pass


# --- The server -------------------------------------------------------------------------------

_PR_SET_PDEATHSIG = 1


def _die_with_parent():
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except Exception:  # noqa: BLE001 - best effort
        pass


class ServerError(TestFailure):
    pass


class Server:
    """One `motwin serve` process. Use as a context manager: the process is killed on exit.

    The serve contract lines it accepts are declared below; a subclass for another module or other
    endpoints overrides BANNER and PORT_ENDPOINTS (canopen_harness.CanServer)."""

    # The banner line; its group is the EEPROM image's path.
    BANNER = r"motwin: tmcm-1636 \(1636V1\d\d\) eeprom (.+)"  # either firmware generation
    # `endpoint KIND 127.0.0.1:PORT` lines: KIND -> the attribute that keeps the port.
    PORT_ENDPOINTS = {"tmcl-tcp": "tcp_port"}

    def __init__(self, motwin, state_dir, tcp=True, pty_link=None, speed=None, extra_args=(), module="tmcm-1636",
                 env=None):
        self.motwin = motwin
        self.state_dir = state_dir
        # Variables added to the test's environment for the server (MOTWIN_CRASH_AT_PERSIST_STEP).
        # A crash hook left set in the developer's shell would kill every other test's server:
        # only a test that asks for it gets it.
        inherited = {k: v for k, v in os.environ.items() if k != "MOTWIN_CRASH_AT_PERSIST_STEP"}
        self.env = dict(inherited, **(env or {}))
        self.args = [motwin, "serve", "--module", module, "--state-dir", state_dir]
        if tcp:
            self.args += ["--tmcl-tcp", "127.0.0.1:0"]
        if pty_link:
            self.args += ["--tmcl-pty", pty_link]
        if speed:
            self.args += ["--speed", speed]
        self.args += list(extra_args)
        self.proc = None
        self.stdout_lines = []
        self.banner = None
        self.eeprom_path = None
        self.tcp_port = None
        for attribute in self.PORT_ENDPOINTS.values():
            setattr(self, attribute, None)
        self.pty_link = None
        self.pty_device = None
        self.tcp_echo = False  # the endpoint line said " echo"
        self.pty_echo = False
        self._stderr_file = None
        self._stdout_thread = None
        self.returncode = None

    # Lifecycle -------------------------------------------------------------------------------
    def start(self, timeout=STARTUP_TIMEOUT):
        self._spawn()
        try:
            self._read_until_ready(timeout)
        except BaseException:
            self.kill()
            raise
        # Keep draining stdout so that the server never blocks on a full pipe.
        self._stdout_thread = threading.Thread(target=self._drain_stdout, daemon=True)
        self._stdout_thread.start()
        return self

    def start_expect_failure(self, timeout=STARTUP_TIMEOUT):
        """Starts the server expecting it to exit before `ready`; returns its exit status."""
        self._spawn()
        try:
            out, _ = self.proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            raise ServerError(f"serve was expected to fail but still runs after {timeout} s")
        self.stdout_lines = out.decode("utf-8", "replace").splitlines()
        self.returncode = self.proc.returncode
        check("ready" not in self.stdout_lines, f"serve printed 'ready' but then exited: {self.stdout_lines!r}")
        return self.returncode

    def _spawn(self):
        """Runs `motwin serve`: stdout a pipe the test reads, stderr an anonymous file."""
        self._open_stderr_file()
        self.proc = subprocess.Popen(self.args, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                     stderr=self._stderr_file, preexec_fn=_die_with_parent, close_fds=True,
                                     env=self.env)

    def _read_until_ready(self, timeout):
        deadline = time.monotonic() + timeout
        fd = self.proc.stdout.fileno()
        buffer = b""
        selector = selectors.DefaultSelector()
        selector.register(fd, selectors.EVENT_READ)
        try:
            while True:
                while b"\n" in buffer:
                    line, buffer = buffer.split(b"\n", 1)
                    text = line.decode("utf-8", "replace").rstrip("\r")
                    self.stdout_lines.append(text)
                    if self._parse_line(text):
                        if buffer:
                            self.stdout_lines.append(buffer.decode("utf-8", "replace"))
                        return
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise ServerError(f"serve not ready after {timeout} s; stdout {self.stdout_lines!r}, "
                                      f"stderr {self.stderr_text()!r}")
                if not selector.select(remaining):
                    continue
                chunk = os.read(fd, 4096)
                if not chunk:
                    self.proc.wait(timeout=5)
                    raise ServerError(f"serve exited with status {self.proc.returncode} before 'ready'; "
                                      f"stdout {self.stdout_lines!r}, stderr {self.stderr_text()!r}")
                buffer += chunk
        finally:
            selector.close()

    def _parse_line(self, text):
        """Returns True on `ready`. Checks each line against the serve contract."""
        if text == "ready":
            check(self.banner is not None, f"'ready' before the banner line: {self.stdout_lines!r}")
            endpoints = [getattr(self, attribute) for attribute in self.PORT_ENDPOINTS.values()] + [self.pty_link]
            check(any(e is not None for e in endpoints), f"'ready' without endpoints: {self.stdout_lines!r}")
            return True
        m = re.fullmatch(self.BANNER, text)
        if m:
            check(self.banner is None, f"two banner lines: {self.stdout_lines!r}")
            self.banner = text
            self.eeprom_path = m.group(1)
            return False
        # A TMCL endpoint given ",echo" (the RS485 transceiver's echo) says " echo" at the end.
        m = re.fullmatch(r"endpoint (\S+) 127\.0\.0\.1:(\d+)( echo)?", text)
        if m and m.group(1) in self.PORT_ENDPOINTS and (m.group(3) is None or m.group(1) == "tmcl-tcp"):
            port = int(m.group(2))
            check(0 < port < 65536, f"bad port in {text!r}")
            setattr(self, self.PORT_ENDPOINTS[m.group(1)], port)
            if m.group(1) == "tmcl-tcp":
                self.tcp_echo = m.group(3) is not None
            return False
        m = re.fullmatch(r"endpoint tmcl-pty (\S+) (/dev/pts/\d+)( echo)?", text)
        if m:
            self.pty_link, self.pty_device, self.pty_echo = m.group(1), m.group(2), m.group(3) is not None
            return False
        raise ServerError(f"unexpected line on serve's stdout: {text!r} (all: {self.stdout_lines!r})")

    def _drain_stdout(self):
        try:
            for line in self.proc.stdout:
                self.stdout_lines.append(line.decode("utf-8", "replace").rstrip("\n"))
        except (OSError, ValueError):
            pass

    def alive(self):
        return self.proc is not None and self.proc.poll() is None

    def bytes_read(self):
        """Bytes the server process has read so far with read() (rchar of /proc/PID/io: its pty
        and files, not what recv() takes from sockets; a pty read in packet mode counts one
        status byte more)."""
        with open(f"/proc/{self.proc.pid}/io") as f:
            for line in f:
                if line.startswith("rchar:"):
                    return int(line.split()[1])
        raise ServerError("no rchar in /proc/PID/io")

    def wait_until_read(self, total, timeout=60.0):
        """Waits until bytes_read() reaches `total` (bytes_read() before a write plus its length):
        the server has taken in what a client wrote. A pause meant for the server (the resync gap
        of the serial link) only starts then: a loaded server may read a burst late."""
        deadline = time.monotonic() + timeout
        while self.bytes_read() < total:
            check(self.alive(), f"server died (status {self.proc.poll()}); stderr {self.stderr_text()!r}")
            if time.monotonic() > deadline:
                raise ServerError(f"the server read {self.bytes_read()} bytes, not {total}, within {timeout} s")
            time.sleep(0.002)

    def stop(self, sig=signal.SIGTERM, timeout=STOP_TIMEOUT):
        """Sends `sig` and checks the clean exit (status 0)."""
        check(self.alive(), f"server died before stop (status {self.proc.poll()}); stderr {self.stderr_text()!r}")
        self.proc.send_signal(sig)
        self.wait_for_exit(timeout, overdue=f"did not exit within {timeout} s of signal {sig}")
        check(self.returncode == 0, f"serve exited with status {self.returncode} after signal {int(sig)}; "
                                    f"stderr {self.stderr_text()!r}")

    def wait_for_exit(self, timeout=STOP_TIMEOUT, overdue=None):
        """Waits for the process to end (after stop()'s signal, or by itself: a crash hook) and
        returns its status (-9: SIGKILL); kills it and fails with `overdue` after `timeout` s."""
        try:
            self.returncode = self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            raise ServerError(f"serve {overdue or f'still runs {timeout} s after it was expected to end'}")
        self._finish()
        return self.returncode

    def kill(self):
        """SIGKILL (no check)."""
        if self.proc is None:
            return
        if self.proc.poll() is None:
            try:
                self.proc.kill()
            except OSError:
                pass
        try:
            self.returncode = self.proc.wait(timeout=STOP_TIMEOUT)
        except subprocess.TimeoutExpired:
            pass
        self._finish()

    def _finish(self):
        if self._stdout_thread is not None:
            self._stdout_thread.join(timeout=5)
            self._stdout_thread = None
        if self.proc is not None and self.proc.stdout is not None:
            try:
                self.proc.stdout.close()
            except OSError:
                pass

    def _open_stderr_file(self):
        # An anonymous file: nothing is left in /tmp whatever happens to this test.
        stderr_fd, stderr_path = tempfile.mkstemp(prefix="motwin-serve-stderr-")
        os.unlink(stderr_path)
        self._stderr_path = None
        self._stderr_file = os.fdopen(stderr_fd, "w+b")

    def stderr_text(self):
        if self._stderr_file is None:
            return ""
        try:
            return os.pread(self._stderr_file.fileno(), 1 << 24, 0).decode("utf-8", "replace")
        except OSError:
            return ""

    def stderr_lines(self):
        return [line for line in self.stderr_text().splitlines() if line.strip()]

    def cleanup(self):
        self.kill()
        if self._stderr_file is not None:
            try:
                self._stderr_file.close()
            except OSError:
                pass
            self._stderr_file = None

    def __enter__(self):
        if self.proc is None:
            self.start()
        return self

    def __exit__(self, *exc):
        self.cleanup()

    # Clients ----------------------------------------------------------------------------------
    def tcp(self):
        check(self.tcp_port is not None, "server has no TCP endpoint")
        return TcpClient(self.tcp_port)

    def serial(self):
        check(self.pty_link is not None, "server has no pty endpoint")
        return SerialClient(self.pty_link)


class Tmcm142Server(Server):
    """`motwin serve --module tmcm-142` with TMCL over TCP on a free port."""

    BANNER = r"motwin: tmcm-142 \(142V1\.06\) eeprom (.+)"

    def __init__(self, motwin, state_dir, **options):
        super().__init__(motwin, state_dir, module="tmcm-142", **options)


class TempDir:
    """A temporary directory removed with its contents, even on failure."""

    def __init__(self, prefix="motwin-test-"):
        self.path = tempfile.mkdtemp(prefix=prefix)

    def __enter__(self):
        return self.path

    def __exit__(self, *exc):
        shutil.rmtree(self.path, ignore_errors=True)


# --- EEPROM image files (layout documented in src/host/eeprom_file.h) -------------------------

EEPROM_MAGIC = b"MOTWINEE"
EEPROM_HEADER_SIZE = 64
# Offsets in the payload (src/core/tmcl/nvm_layout.h, one motor).
NVM_AXIS_OFFSET = 0
NVM_GLOBAL_OFFSET = 256 * 4
NVM_USER_OFFSET = NVM_GLOBAL_OFFSET + 256 * 4


def encode_eeprom_image(module_name, layout_version, payload, format_version=1, firmware=""):
    header = bytearray(EEPROM_HEADER_SIZE)
    header[0:8] = EEPROM_MAGIC
    struct.pack_into("<II", header, 8, format_version, EEPROM_HEADER_SIZE)
    name = module_name.encode("ascii")[:15]
    header[16:16 + len(name)] = name
    recorded = firmware.encode("ascii")[:15]
    header[32:32 + len(recorded)] = recorded
    struct.pack_into("<III", header, 48, layout_version, len(payload), zlib.crc32(payload) & 0xFFFFFFFF)
    struct.pack_into("<I", header, 60, zlib.crc32(bytes(header[:60])) & 0xFFFFFFFF)
    return bytes(header) + bytes(payload)


class EepromImage:
    """A parsed image file; `problem` is None when it is valid."""

    def __init__(self, data):
        self.data = data
        self.problem = None
        self.module_name = None
        self.firmware = None
        self.layout_version = None
        self.payload = b""
        if len(data) < EEPROM_HEADER_SIZE:
            self.problem = f"{len(data)} bytes, shorter than the header"
            return
        if data[:8] != EEPROM_MAGIC:
            self.problem = "bad magic"
            return
        if struct.unpack_from("<I", data, 60)[0] != zlib.crc32(data[:60]) & 0xFFFFFFFF:
            self.problem = "header CRC"
            return
        self.module_name = data[16:32].split(b"\0", 1)[0].decode("ascii", "replace")
        self.firmware = data[32:48].split(b"\0", 1)[0].decode("ascii", "replace")
        self.layout_version, payload_size, payload_crc = struct.unpack_from("<III", data, 48)
        self.payload = data[EEPROM_HEADER_SIZE:]
        if len(self.payload) != payload_size:
            self.problem = f"payload {len(self.payload)} bytes, header says {payload_size}"
        elif zlib.crc32(self.payload) & 0xFFFFFFFF != payload_crc:
            self.problem = "payload CRC"

    def slot(self, offset):
        return struct.unpack_from("<i", self.payload, offset)[0]

    def axis_parameter(self, number):
        return self.slot(NVM_AXIS_OFFSET + number * 4)

    def global_parameter(self, number):
        return self.slot(NVM_GLOBAL_OFFSET + number * 4)

    def user_variable(self, number):
        return self.slot(NVM_USER_OFFSET + number * 4)


def read_eeprom_image(path):
    with open(path, "rb") as f:
        return EepromImage(f.read())


def damaged_lines(lines):
    return [line for line in lines if "damaged" in line.lower()]


# --- Running -----------------------------------------------------------------------------------

def parse_arguments():
    parser = argparse.ArgumentParser()
    parser.add_argument("--motwin", required=True, help="path to build/motwin")
    parser.add_argument("--only", action="append", help="run only these tests (by function name)")
    parser.add_argument("--watchdog", type=float, default=540.0, help="abort the whole script after this many seconds")
    return parser.parse_args()


def run_tests(tests):
    """Runs test functions `test(motwin)` in order; exit status 0 only if all pass."""
    args = parse_arguments()
    motwin = os.path.abspath(args.motwin)
    if not os.access(motwin, os.X_OK):
        print(f"FAIL: {motwin} is not an executable", flush=True)
        sys.exit(1)

    def on_watchdog(signum, frame_):
        raise TimeoutError(f"watchdog: script still running after {args.watchdog} s")

    signal.signal(signal.SIGALRM, on_watchdog)
    signal.alarm(int(args.watchdog))
    failures = 0
    skipped = 0
    ran = 0
    script_start = time.monotonic()
    for test in tests:
        if args.only and test.__name__ not in args.only:
            continue
        ran += 1
        start = time.monotonic()
        try:
            test(motwin)
        except Skipped as reason:
            skipped += 1
            print(f"skip {test.__name__}: {reason}", flush=True)
        except Exception:  # noqa: BLE001 - report every failure, keep going
            failures += 1
            print(f"FAIL {test.__name__} ({time.monotonic() - start:.2f} s)", flush=True)
            traceback.print_exc()
            sys.stdout.flush()
        else:
            print(f"ok   {test.__name__} ({time.monotonic() - start:.2f} s)", flush=True)
    signal.alarm(0)
    print(f"{'FAILED' if failures else 'passed'}: {failures} failure(s), "
          f"{f'{skipped} skipped, ' if skipped else ''}{time.monotonic() - script_start:.2f} s", flush=True)
    sys.exit(1 if failures else SKIP_STATUS if ran and skipped == ran else 0)
