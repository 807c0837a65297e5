"""Helpers for the misbehaving-client and load tests (test_garbage_clients.py,
test_load_connections.py, test_slcan_clients.py, test_valgrind_serve.py): workers that misbehave
beside a well-behaved client, the server's memory and descriptors from /proc, readers of
CR/BEL- or `>`-terminated units over TCP or a pseudo-terminal, and socketcand / SLCAN clients
speaking raw text (what is checked is the wire, not a library's view of it).

Builds on motwin_harness (checks, TestFailure). No timing is ever asserted here: every deadline
is a liveness bound (an answer must come at all), generous enough for the ASan build on a loaded
machine.
"""

import os
import select
import socket
import struct
import termios
import threading
import time
import tty

from motwin_harness import TestFailure, check, check_equal

MIB = 1024 * 1024


# --- Misbehaving clients beside a well-behaved one --------------------------------------------

class Worker(threading.Thread):
    """Runs body(*args) in a thread; keeps its note (what it returned) or its failure."""

    def __init__(self, body, *args, name=None):
        super().__init__(name=name or body.__name__, daemon=True)
        self.body = body
        self.args = args
        self.failure = None
        self.note = ""

    def run(self):
        try:
            self.note = self.body(*self.args) or ""
        except Exception as error:  # noqa: BLE001 - reported by the main thread
            self.failure = f"{self.name}: {error!r}"


def run_beside(workers, good_round, min_rounds=20, timeout=120.0, on_round=None, what="misbehaving clients"):
    """Starts the workers and runs good_round(i) in this thread until every worker has finished
    and at least `min_rounds` rounds ran (on_round() after each, e.g. a memory sample); fails with
    the workers' failures, prints their notes and returns the number of rounds."""
    for w in workers:
        w.start()
    rounds = 0
    deadline = time.monotonic() + timeout
    while any(w.is_alive() for w in workers) or rounds < min_rounds:
        check(time.monotonic() < deadline, f"{what} still running after {timeout} s")
        good_round(rounds)
        if on_round is not None:
            on_round()
        rounds += 1
    for w in workers:
        w.join(10.0)
        check(not w.is_alive(), f"{w.name} did not finish")
    failures = [w.failure for w in workers if w.failure]
    check(not failures, f"{what} failed: {failures}")
    for w in workers:
        print(f"  {w.name}: {w.note}", flush=True)
    return rounds


# --- The server process from /proc ----------------------------------------------------------

RSS_GROWTH_LIMIT = 48 * MIB
RSS_GROWTH_LIMIT_ASAN = 256 * MIB  # AddressSanitizer's quarantine holds freed memory


class Memory:
    """VmRSS of the server, sampled by the test while the load runs; check() bounds its growth
    over the figure at construction."""

    def __init__(self, pid):
        self.pid = pid
        with open(f"/proc/{pid}/maps") as f:
            self.asan = "libasan" in f.read()
        self.baseline = self.rss()
        self.peak = self.baseline

    def rss(self):
        with open(f"/proc/{self.pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
        raise AssertionError("no VmRSS")

    def sample(self):
        self.peak = max(self.peak, self.rss())
        return self.peak

    def check(self, when):
        self.sample()
        limit = RSS_GROWTH_LIMIT_ASAN if self.asan else RSS_GROWTH_LIMIT
        growth = self.peak - self.baseline
        print(f"  {when}: RSS {self.baseline / MIB:.1f} MiB idle, peak {self.peak / MIB:.1f} MiB "
              f"(+{growth / MIB:.1f}, limit +{limit / MIB:.0f}{' ASan' if self.asan else ''})", flush=True)
        check(growth <= limit, f"{when}: RSS grew by {growth / MIB:.1f} MiB (limit {limit / MIB:.0f} MiB)")


def open_descriptors(pid):
    return len(os.listdir(f"/proc/{pid}/fd"))


def descriptor_targets(pid):
    targets = []
    for fd in sorted(os.listdir(f"/proc/{pid}/fd"), key=int):
        try:
            targets.append(f"{fd}:{os.readlink(f'/proc/{pid}/fd/{fd}')}")
        except OSError:
            pass
    return ", ".join(targets)


def check_descriptors_return(pid, expected, what, timeout=60.0):
    """The server notices closed connections on its own schedule: waits (up to `timeout`) until
    it holds `expected` descriptors again, then checks."""
    deadline = time.monotonic() + timeout
    while open_descriptors(pid) != expected and time.monotonic() < deadline:
        time.sleep(0.05)
    check_equal(open_descriptors(pid), expected, f"server descriptors {what} ({descriptor_targets(pid)})")


# --- Units over a byte stream -----------------------------------------------------------------

def write_and_read_some(fd, pending, timeout=1.0):
    """One step of a client that writes `pending` while reading whatever comes, as a serial
    client does (a server that stops reading while its replies back up would stall a client that
    writes everything first): waits until `fd` is readable or, with something pending, writable;
    writes up to 4 KiB and reads what is there. Returns (what is still pending, what was read)."""
    readable, writable, _ = select.select([fd], [fd] if pending else [], [], timeout)
    if writable and pending:
        try:
            pending = pending[os.write(fd, pending[:4096]):]
        except BlockingIOError:
            pass
    return pending, os.read(fd, 65536) if readable else b""


def as_bytes(data):
    return data.encode("latin-1") if isinstance(data, str) else bytes(data)


class UnitStream:
    """Reads units that end with one of `terminators` (b">" for socketcand elements, CR/BEL for
    SLCAN answers) from a byte stream; UnitSocket and UnitPty supply the stream."""

    def __init__(self, terminators):
        self.terminators = terminators
        self.buffer = b""
        self.position = 0  # read up to here

    # The stream: bytes (b"" at its end) or None when nothing came within `timeout`.
    def _receive(self, timeout):
        raise NotImplementedError

    def _send(self, data):
        raise NotImplementedError

    def send(self, data):
        self._send(as_bytes(data))

    def send_slowly(self, data, pause=0.01):
        for byte in as_bytes(data):
            self._send(bytes([byte]))
            time.sleep(pause)

    def feed(self, chunk):
        self.buffer = self.buffer[self.position:] + chunk
        self.position = 0

    def pop_unit(self):
        """The next complete unit already received, or None."""
        ends = [i for i in (self.buffer.find(t, self.position) for t in self.terminators) if i >= 0]
        if not ends:
            return None
        end = min(ends) + 1
        unit = self.buffer[self.position:end]
        self.position = end
        if self.position > 65536:  # drop what was read without copying per unit
            self.buffer = self.buffer[self.position:]
            self.position = 0
        return unit.decode("latin-1")

    def read_unit(self, timeout=5.0):
        deadline = time.monotonic() + timeout
        while True:
            unit = self.pop_unit()
            if unit is not None:
                return unit
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TestFailure(f"nothing complete within {timeout} s (have {self.buffer[self.position:][-80:]!r})")
            chunk = self._receive(remaining)
            if chunk is None:
                continue
            if not chunk:
                raise TestFailure("connection closed by the server")
            self.feed(chunk)

    def read_until(self, predicate, timeout=5.0, what="answer"):
        deadline = time.monotonic() + timeout
        while True:
            unit = self.read_unit(max(0.01, deadline - time.monotonic()))
            if predicate(unit):
                return unit
            if time.monotonic() > deadline:
                raise TestFailure(f"no {what} within {timeout} s")

    def drain(self, duration):
        """Discards what arrives within `duration` seconds (the bus keeps talking meanwhile)."""
        deadline = time.monotonic() + duration
        try:
            while time.monotonic() < deadline:
                chunk = self._receive(max(0.01, deadline - time.monotonic()))
                if not chunk:
                    break
        except OSError:
            pass
        self.buffer = b""
        self.position = 0

    def read_to_eof(self, timeout):
        """Reads until the server closes the connection; returns the byte count, or None if the
        connection is still open after `timeout` seconds."""
        total = 0
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                chunk = self._receive(max(0.01, deadline - time.monotonic()))
            except ConnectionResetError:
                return total
            if chunk is None:
                continue
            if not chunk:
                return total
            total += len(chunk)
        return None


class UnitSocket(UnitStream):
    """A TCP client on 127.0.0.1 (a small receive buffer makes a never-reading client's window
    fill quickly)."""

    def __init__(self, port, terminators, rcvbuf=None):
        super().__init__(terminators)
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        if rcvbuf:
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
        self.sock.settimeout(5.0)
        self.sock.connect(("127.0.0.1", port))
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    def _receive(self, timeout):
        self.sock.settimeout(timeout)
        try:
            return self.sock.recv(65536)
        except socket.timeout:
            return None

    def _send(self, data):
        self.sock.settimeout(30.0)
        self.sock.sendall(data)

    def close(self):
        try:
            self.sock.close()
        except OSError:
            pass


class UnitPty(UnitStream):
    """A client of a pseudo-terminal endpoint: the link opened raw, its input flushed as pyserial
    does on open (the server then drops what it still held for an earlier client)."""

    def __init__(self, link, terminators):
        super().__init__(terminators)
        self.fd = os.open(link, os.O_RDWR | os.O_NOCTTY)
        tty.setraw(self.fd)
        self.flush_input()

    def flush_input(self):
        termios.tcflush(self.fd, termios.TCIFLUSH)
        self.buffer = b""
        self.position = 0

    def _receive(self, timeout):
        readable, _, _ = select.select([self.fd], [], [], timeout)
        if not readable:
            return None
        try:
            return os.read(self.fd, 65536)
        except OSError:
            return b""

    def _send(self, data):
        view = memoryview(data)
        while view:
            view = view[os.write(self.fd, view):]

    def close(self):
        try:
            os.close(self.fd)
        except OSError:
            pass


# --- socketcand and SLCAN, raw ------------------------------------------------------------

# An expedited SDO upload of 1000 (device type) and the TMCM-3216's answer (0xFFFF0192).
UPLOAD_1000 = bytes([0x40, 0x00, 0x10, 0, 0, 0, 0, 0])
ANSWER_1000 = bytes.fromhex("430010009201FFFF")


def socketcand_client(port, rcvbuf=None):
    """A socketcand client in raw mode."""
    c = UnitSocket(port, (b">",), rcvbuf)
    check_equal(c.read_unit().strip(), "< hi >", "socketcand greeting")
    c.send("< open can0 >")
    check_equal(c.read_unit().strip(), "< ok >", "open")
    c.send("< rawmode >")
    check_equal(c.read_unit().strip(), "< ok >", "rawmode")
    return c


def send_element(cob_id, data, extended=False):
    """`< send ID LEN B0 .. >`; an 8-digit ID is an extended one."""
    return "< send %s %d %s >" % (f"{cob_id:08X}" if extended else f"{cob_id:03X}", len(data),
                                  " ".join(f"{b:02X}" for b in data))


def socketcand_frame(unit):
    """(ID, extended, data) of a ` < frame ID SEC.USEC HEX >` element, None for anything else."""
    parts = unit.split()
    if len(parts) < 5 or parts[0] != "<" or parts[1] != "frame" or parts[-1] != ">":
        return None
    return int(parts[2], 16), len(parts[2]) == 8, bytes.fromhex(parts[4]) if len(parts) == 6 else b""


def sdo_element(node, data):
    return send_element(0x600 + node, data)


def sdo_answer_of(node, index=None):
    """A predicate for the socketcand element of node's SDO answer (to an object, if given: two
    SDO clients of expedited transfers tell their answers apart by the multiplexer)."""
    def is_answer(unit):
        frame = socketcand_frame(unit)
        if frame is None or frame[0] != 0x580 + node or frame[1] or len(frame[2]) != 8:
            return False
        return index is None or frame[2][1] | frame[2][2] << 8 == index
    return is_answer


def sdo_answer_data(unit):
    return socketcand_frame(unit)[2]


def sdo_1017_round(client, node, i):
    """A well-behaved socketcand client's round: writes the heartbeat time 1017 and reads it
    back (expedited), picking the answers to 1017 out of whatever else the bus carries."""
    value = 100 + i % 1000
    client.send(sdo_element(node, [0x2B, 0x17, 0x10, 0, value & 0xFF, value >> 8, 0, 0]))
    answer = sdo_answer_data(client.read_until(sdo_answer_of(node, 0x1017), timeout=10.0, what="SDO answer"))
    check_equal(answer[:4], bytes([0x60, 0x17, 0x10, 0]), f"1017 = {value}")
    client.send(sdo_element(node, [0x40, 0x17, 0x10, 0, 0, 0, 0, 0]))
    answer = sdo_answer_data(client.read_until(sdo_answer_of(node, 0x1017), timeout=10.0, what="SDO answer"))
    check_equal(struct.unpack_from("<H", answer, 4)[0], value, "1017 read back")


SLCAN_UNIT_ENDS = (b"\r", b"\a")


def slcan_line(cob_id, data):
    """A standard data frame as an SLCAN line (without the CR)."""
    return "t%03X%d%s" % (cob_id, len(data), bytes(data).hex().upper())


def is_slcan_frame(unit):
    return len(unit) > 1 and unit[0] in "tTrR"


def slcan_answer(c):
    """The next adapter answer (CR, BEL or a reply line), skipping the bus frames an open channel
    passes on in between."""
    return c.read_until(lambda u: not is_slcan_frame(u), what="SLCAN answer")


def slcan_open(c):
    c.send("O\r")
    check_equal(slcan_answer(c), "\r", "SLCAN open")
    return c


def slcan_client(port, rcvbuf=None):
    """An SLCAN adapter over TCP with its channel open."""
    return slcan_open(UnitSocket(port, SLCAN_UNIT_ENDS, rcvbuf))
