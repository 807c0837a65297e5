#!/usr/bin/python3
"""Misbehaving hosts must not disturb a well-behaved one.

Over TCP, while a well-behaved client loops SAP/GAP/SGP/GGP and asserts every reply (each within
2 s), other clients: send random bytes (never a frame for module 1) and get nothing back, then
pause and get a good frame answered; send half frames and disconnect; send frames byte by byte
with pauses; connect and drop at once (50 of them, some with a reset); send bad-checksum frames
and get one status-1 reply each; send requests and never read. Afterwards the server is alive,
answers and exits cleanly. More idle connections than the server serves at once leave the
existing ones working.

Over the pty: garbage, a pause longer than 5 ms, then a good frame is answered correctly
(resync by pause); garbage without a pause costs at most one checksum-error reply.

On a TMCM-3216's CAN endpoints (socketcand and SLCAN over TCP), while a well-behaved socketcand
client loops SDO downloads and uploads and checks every answer (it is the node's only SDO
client, as CANopen requires): 64 KiB of random bytes, then a good command is served (resync at
the next element or CR); elements and command lines typed a byte every 10 ms (slowloris) are
served; half elements and half lines followed by a disconnect;
50 connect/drop (some with a reset); an overlong SLCAN line costs exactly one BEL; a client on
each endpoint that never reads while another floods the bus with 150 000 frames is disconnected
(its unread output is bounded) and the others keep working.
"""

import os
import random
import socket
import struct
import sys
import threading
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import CanServer  # noqa: E402
from motwin_harness import (  # noqa: E402
    BANK_USER, GAP, GGP, SAP, SGP, STATUS_OK, Server, TcpClient, TempDir, TestFailure, check, check_equal,
    expect_reply, frame, parse_reply, run_tests,
)

CHECKSUM_ERROR_REPLY = bytes.fromhex("02 01 01 00 00 00 00 00 04")
TCP_RESYNC_PAUSE = 0.25  # longer than the server's TCP resync gap (100 ms, src/host/tcp_server.h)


def random_garbage(rng, length):
    """Random bytes in which no byte is 0x01, so no alignment ever yields a frame for module 1."""
    return bytes(b if b != 1 else 0 for b in (rng.randrange(256) for _ in range(length)))


class Worker(threading.Thread):
    def __init__(self, name, body, port):
        super().__init__(name=name, daemon=True)
        self.body = body
        self.port = port
        self.failure = None
        self.note = ""

    def run(self):
        try:
            self.note = self.body(self.port) or ""
        except Exception as error:  # noqa: BLE001 - reported by the main thread
            self.failure = f"{self.name}: {error!r}"


def random_bytes_client(port):
    rng = random.Random(7)
    with TcpClient(port) as c:
        for _ in range(16):
            c.send_raw(random_garbage(rng, 4096))
        data = c.read_available(0.5)
        check(data == b"", f"random bytes (no frame for module 1) got an answer: {data[:32].hex(' ')}")
        time.sleep(TCP_RESYNC_PAUSE)
        expect_reply(c.request(GGP, 200, BANK_USER), GGP, STATUS_OK, what="good frame after random bytes and a pause")
    return "64 KiB of garbage, no reply, resynced by pause"


def half_frame_clients(port):
    for i in range(20):
        with TcpClient(port) as c:
            c.send_raw(frame(SAP, 43, 0, 9999)[: 1 + i % 8])
    return "20 half frames"


def slow_client(port):
    with TcpClient(port) as c:
        for i in range(4):
            request = frame(SGP, 201, BANK_USER, 5000 + i)
            for byte in request:
                c.send_raw(bytes([byte]))
                time.sleep(0.01)
            expect_reply(parse_reply(c.read_exact(9, 5.0)), SGP, STATUS_OK, 5000 + i, f"slow SGP {i}")
            for byte in frame(GGP, 201, BANK_USER):
                c.send_raw(bytes([byte]))
                time.sleep(0.003)
            expect_reply(parse_reply(c.read_exact(9, 5.0)), GGP, STATUS_OK, 5000 + i, f"slow GGP {i}")
    return "8 frames byte by byte"


def connect_and_drop_clients(port):
    for i in range(50):
        s = socket.create_connection(("127.0.0.1", port), timeout=5.0)
        if i % 3 == 0:
            s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))  # RST on close
        if i % 5 == 0:
            s.sendall(b"\x01")
        s.close()
    return "50 connect/drop"


def checksum_error_client(port):
    bad = bytearray(frame(GAP, 44))
    bad[8] ^= 0x5A
    with TcpClient(port) as c:
        c.send_raw(bytes(bad) * 100)
        data = c.read_exact(900, 10.0)
        check(data == CHECKSUM_ERROR_REPLY * 100, f"100 bad frames: replies {data[:27].hex(' ')}...")
        expect_reply(c.request(GAP, 43), GAP, STATUS_OK, 4000, "good frame after bad checksums")
    return "100 checksum errors answered"


def never_reading_client(port):
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)  # fill up quickly
    s.settimeout(5.0)
    s.connect(("127.0.0.1", port))
    s.setblocking(False)
    chunk = frame(GAP, 44) * 1000
    sent = 0
    outcome = "sent the limit"
    blocked_since = None
    # Normally over within 2 s; the deadline only bounds a server that never pushes back (a
    # sanitizer build on a loaded machine reads slowly, and the kernel holds a few MiB of replies).
    deadline = time.monotonic() + 40.0
    try:
        while sent < 16 * 1024 * 1024 and time.monotonic() < deadline:
            try:
                sent += s.send(chunk)
                blocked_since = None
            except BlockingIOError:
                blocked_since = blocked_since or time.monotonic()
                if time.monotonic() - blocked_since > 1.0:
                    outcome = "back-pressure (server stopped reading)"
                    break
                time.sleep(0.01)
            except (ConnectionResetError, BrokenPipeError):
                outcome = "disconnected by the server"
                break
    finally:
        s.close()
    # Either way the server bounds what it holds for this client.
    check(outcome != "sent the limit", f"never-reading client: {sent} bytes accepted without back-pressure or disconnect")
    return f"never read: {sent} bytes sent, {outcome}"


WORKERS = [random_bytes_client, half_frame_clients, slow_client, connect_and_drop_clients, checksum_error_client,
           never_reading_client]


def good_client_round(c, i):
    value = 100 + (i * 37) % 99000  # AP 44 takes 0..100000
    start = time.monotonic()
    expect_reply(c.request(SAP, 44, 0, value), SAP, STATUS_OK, value, f"good SAP 44 {value}")
    expect_reply(c.request(GAP, 44), GAP, STATUS_OK, value, "good GAP 44")
    expect_reply(c.request(SGP, 7, BANK_USER, -value), SGP, STATUS_OK, -value, "good SGP")
    expect_reply(c.request(GGP, 7, BANK_USER), GGP, STATUS_OK, -value, "good GGP")
    expect_reply(c.request(GAP, 43), GAP, STATUS_OK, 4000, "good GAP 43")
    return time.monotonic() - start


def test_tcp_garbage_clients(motwin):
    with TempDir() as tmp:
        with Server(motwin, os.path.join(tmp, "state")) as server:
            good = server.tcp()
            try:
                good.sap(44, 2000)
                workers = [Worker(w.__name__, w, server.tcp_port) for w in WORKERS]
                for w in workers:
                    w.start()
                rounds = 0
                slowest = 0.0
                deadline = time.monotonic() + 60.0
                while any(w.is_alive() for w in workers) or rounds < 50:
                    check(time.monotonic() < deadline, "garbage clients still running after 60 s")
                    slowest = max(slowest, good_client_round(good, rounds))
                    rounds += 1
                for w in workers:
                    w.join(10.0)
                    check(not w.is_alive(), f"{w.name} did not finish")
                failures = [w.failure for w in workers if w.failure]
                check(not failures, f"garbage clients failed: {failures}")
                for w in workers:
                    print(f"  {w.name}: {w.note}", flush=True)
                print(f"  well-behaved client: {rounds} rounds of 5 requests, slowest round {slowest * 1000:.1f} ms",
                      flush=True)
                # The module's state is what the well-behaved client left.
                good.sap(44, 2000)
                check_equal(good.gap(44), 2000, "AP 44 afterwards")
                check_equal(good.gap(43), 4000, "AP 43 never touched by the garbage")
            finally:
                good.close()
            check(server.alive(), "server died")
            with server.tcp() as c:
                check_equal(c.ggp(201, BANK_USER), 5003, "slow client's last value")
                check_equal(c.version_string(), b"1636V109", "version afterwards")
            server.stop()


def test_many_idle_connections(motwin):
    """More idle connections than the server takes at once (64): the established ones work,
    and after they go, new connections are served."""
    with TempDir() as tmp:
        with Server(motwin, os.path.join(tmp, "state")) as server:
            good = server.tcp()
            idle = []
            try:
                for _ in range(80):
                    # Paced: the server listens with a backlog of 16, and a burst of connects
                    # beyond it costs SYN retransmissions (1 s, 3 s ...), not what this is about.
                    idle.append(socket.create_connection(("127.0.0.1", server.tcp_port), timeout=15.0))
                    time.sleep(0.002)
                for i in range(20):
                    good_client_round(good, i)
            finally:
                for s in idle:
                    s.close()
            try:
                start = time.monotonic()
                deadline = start + 10.0
                attempts = []
                while True:  # the server notices the closed sockets on its own schedule
                    try:
                        with server.tcp() as c:
                            check_equal(c.version_string(), b"1636V109", "new connection after the idle ones")
                        break
                    except Exception as error:  # noqa: BLE001
                        attempts.append(f"{time.monotonic() - start:.3f} s: {error!r}")
                        if time.monotonic() > deadline:
                            raise
                        time.sleep(0.1)
                if attempts:
                    print(f"  new connection after the idle ones: {len(attempts)} failed attempt(s): {attempts}",
                          flush=True)
                good_client_round(good, 99)
            finally:
                good.close()
            server.stop()


def test_pty_resync_by_pause(motwin):
    with TempDir() as tmp:
        link = os.path.join(tmp, "tmcm1636")
        with Server(motwin, os.path.join(tmp, "state"), tcp=False, pty_link=link) as server:
            with server.serial() as c:
                c.sap(43, 3210)
                rng = random.Random(99)
                cases = [
                    ("half frame for module 1", frame(SAP, 43, 0, 9999)[:4]),
                    ("one byte", b"\x01"),
                    ("foreign frame and 5 random bytes", frame(SAP, 43, 0, 1, address=9) + random_garbage(rng, 5)),
                    ("2000 random bytes", random_garbage(rng, 2000) + b"\x01\x05"),
                ]
                for name, garbage in cases:
                    c.send_raw(garbage)
                    time.sleep(0.05)  # > 5 ms
                    c.expect_no_reply(0.05, f"{name}")
                    expect_reply(c.request(GAP, 43), GAP, STATUS_OK, 3210, f"GAP 43 after {name} and a pause")
                    c.expect_no_reply(0.05, f"after the reply ({name})")
                # No pause: 7 bytes of a frame for module 1 run into the good frame; that costs one
                # checksum-error reply (9 bytes), the rest is dropped by the next pause.
                c.send_raw(frame(SAP, 43, 0, 9999)[:7] + frame(GAP, 43))
                check_equal(c.read_exact(9), CHECKSUM_ERROR_REPLY, "misaligned frame")
                time.sleep(0.05)
                c.expect_no_reply(0.05, "after the misaligned frame")
                expect_reply(c.request(GAP, 43), GAP, STATUS_OK, 3210, "GAP 43 after resync")
            server.stop()


# --- CAN endpoints: socketcand and SLCAN over TCP -----------------------------------------------

CAN_NODE = 5
FLOOD_FRAMES = 150_000


class LineSocket:
    """A TCP client reading units that end with one of `terminators` (b">" for socketcand
    elements, CR/BEL for SLCAN answers)."""

    def __init__(self, port, terminators, rcvbuf=None):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        if rcvbuf:
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
        self.sock.settimeout(5.0)
        self.sock.connect(("127.0.0.1", port))
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.terminators = terminators
        self.buffer = b""
        self.position = 0  # read up to here

    def send(self, data):
        self.sock.sendall(data.encode("latin-1") if isinstance(data, str) else data)

    def send_slowly(self, data, pause=0.01):
        for byte in data.encode("latin-1"):
            self.sock.sendall(bytes([byte]))
            time.sleep(pause)

    def read_unit(self, timeout=5.0):
        deadline = time.monotonic() + timeout
        while True:
            ends = [i for i in (self.buffer.find(t, self.position) for t in self.terminators) if i >= 0]
            if ends:
                end = min(ends) + 1
                unit = self.buffer[self.position:end]
                self.position = end
                if self.position > 65536:  # drop what was read without copying per unit
                    self.buffer = self.buffer[self.position:]
                    self.position = 0
                return unit.decode("latin-1")
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TestFailure(f"nothing complete within {timeout} s (have {self.buffer[self.position:][-80:]!r})")
            self.sock.settimeout(remaining)
            try:
                chunk = self.sock.recv(65536)
            except socket.timeout:
                continue
            if not chunk:
                raise TestFailure("connection closed by the server")
            self.buffer = self.buffer[self.position:] + chunk
            self.position = 0

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
                self.sock.settimeout(max(0.01, deadline - time.monotonic()))
                try:
                    if not self.sock.recv(65536):
                        break
                except socket.timeout:
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
            self.sock.settimeout(max(0.01, deadline - time.monotonic()))
            try:
                chunk = self.sock.recv(65536)
            except socket.timeout:
                continue
            except ConnectionResetError:
                return total
            if not chunk:
                return total
            total += len(chunk)
        return None

    def close(self):
        try:
            self.sock.close()
        except OSError:
            pass


def socketcand_client(port, rcvbuf=None):
    c = LineSocket(port, (b">",), rcvbuf)
    check_equal(c.read_unit().strip(), "< hi >", "socketcand greeting")
    c.send("< open can0 >")
    check_equal(c.read_unit().strip(), "< ok >", "open")
    c.send("< rawmode >")
    check_equal(c.read_unit().strip(), "< ok >", "rawmode")
    return c


def sdo_element(data):
    return "< send %03X 8 %s >" % (0x600 + CAN_NODE, " ".join(f"{b:02X}" for b in data))


def is_sdo_answer(unit):
    parts = unit.split()
    return len(parts) >= 5 and parts[1] == "frame" and int(parts[2], 16) == 0x580 + CAN_NODE


def sdo_answer_data(unit):
    return bytes.fromhex(unit.split()[4])


UPLOAD_1000 = [0x40, 0x00, 0x10, 0, 0, 0, 0, 0]
ANSWER_1000 = bytes.fromhex("430010009201FFFF")


def slcan_answer(c):
    """The next adapter answer (CR, BEL or a reply line), skipping the bus frames an open channel
    passes on in between."""
    return c.read_until(lambda u: len(u) == 1 or u[0] not in "tTrR", what="SLCAN answer")


def slcan_client(port, rcvbuf=None):
    c = LineSocket(port, (b"\r", b"\a"), rcvbuf)
    c.send("O\r")
    check_equal(c.read_unit(), "\r", "SLCAN open")
    return c


SLCAN_UPLOAD_1000 = "t%03X8%s" % (0x600 + CAN_NODE, bytes(UPLOAD_1000).hex().upper())
SLCAN_ANSWER_1000 = "t%03X8%s\r" % (0x580 + CAN_NODE, ANSWER_1000.hex().upper())


def can_garbage_socketcand(ports):
    rng = random.Random(3216)
    c = socketcand_client(ports["socketcand"])
    try:
        c.send(bytes(rng.randrange(256) for _ in range(65536)))
        c.send(" > ")  # ends whatever element the garbage left open
        c.drain(0.3)
        c.send("< echo >")
        c.read_until(lambda u: u.strip() == "< echo >", what="echo after garbage")
    finally:
        c.close()
    return "64 KiB of random bytes, then an echo served"


def can_garbage_slcan(ports):
    rng = random.Random(1013)
    c = slcan_client(ports["slcan"])
    try:
        c.send(bytes(rng.randrange(256) for _ in range(65536)) + b"\r")
        c.drain(0.3)
        c.send("x" * 10000 + "\r")
        check_equal(slcan_answer(c), "\a", "one BEL for an overlong line")
        c.send("V\r")
        check_equal(slcan_answer(c), "V1013\r", "version after garbage")
        c.send("F\r")
        check_equal(slcan_answer(c), "F00\r", "status flags after garbage")
    finally:
        c.close()
    return "64 KiB of random bytes, an overlong line, then version and flags served"


def can_slowloris(ports):
    c = LineSocket(ports["socketcand"], (b">",))
    try:
        check_equal(c.read_unit().strip(), "< hi >", "greeting")
        c.send_slowly("< open can0 >")
        check_equal(c.read_unit().strip(), "< ok >", "slow open")
        c.send_slowly("< rawmode >")
        check_equal(c.read_unit().strip(), "< ok >", "slow rawmode")
        c.send_slowly("< echo >")
        c.read_until(lambda u: u.strip() == "< echo >", what="slow echo")
    finally:
        c.close()
    s = slcan_client(ports["slcan"])
    try:
        s.send_slowly("t3212ABCD\r")
        check_equal(slcan_answer(s), "z\r", "slow SLCAN frame acknowledged")
        s.send_slowly("V\r")
        check_equal(slcan_answer(s), "V1013\r", "slow SLCAN version")
    finally:
        s.close()
    return "socketcand and SLCAN commands a byte every 10 ms served"


def can_half_and_drop(ports):
    for i in range(50):
        port = ports["socketcand"] if i % 2 == 0 else ports["slcan"]
        s = socket.create_connection(("127.0.0.1", port), timeout=5.0)
        if i % 3 == 0:
            s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))  # RST on close
        if i % 5 == 0:
            s.sendall(b"< send 605 8 40" if port == ports["socketcand"] else b"t6058400")
        s.close()
    return "50 half elements/lines and connect/drop"


def test_can_endpoint_garbage_clients(motwin):
    with TempDir() as tmp:
        server = CanServer(motwin, os.path.join(tmp, "state"), node_id=CAN_NODE,
                           can=("socketcand:127.0.0.1:0", "slcan-tcp:127.0.0.1:0"))
        with server:
            ports = {"socketcand": server.can_port, "slcan": server.slcan_port}
            good = socketcand_client(ports["socketcand"])
            try:
                workers = [Worker(w.__name__, w, ports) for w in
                           (can_garbage_socketcand, can_garbage_slcan, can_slowloris, can_half_and_drop)]
                for w in workers:
                    w.start()
                rounds = 0
                deadline = time.monotonic() + 60.0
                while any(w.is_alive() for w in workers) or rounds < 30:
                    check(time.monotonic() < deadline, "CAN garbage clients still running after 60 s")
                    value = 100 + rounds % 1000
                    good.send(sdo_element([0x2B, 0x17, 0x10, 0, value & 0xFF, value >> 8, 0, 0]))
                    check_equal(sdo_answer_data(good.read_until(is_sdo_answer))[:4], bytes([0x60, 0x17, 0x10, 0]),
                                f"good 1017 = {value}")
                    good.send(sdo_element([0x40, 0x17, 0x10, 0, 0, 0, 0, 0]))
                    answer = sdo_answer_data(good.read_until(is_sdo_answer))
                    check_equal(struct.unpack_from("<H", answer, 4)[0], value, "good 1017 read back")
                    rounds += 1
                for w in workers:
                    w.join(10.0)
                    check(not w.is_alive(), f"{w.name} did not finish")
                failures = [w.failure for w in workers if w.failure]
                check(not failures, f"CAN garbage clients failed: {failures}")
                for w in workers:
                    print(f"  {w.name}: {w.note}", flush=True)
                print(f"  well-behaved socketcand client: {rounds} rounds of download + upload", flush=True)
            finally:
                good.close()
            check(server.alive(), "server died")
            server.stop()


def test_can_never_reading_clients_are_dropped(motwin):
    """A client on each CAN endpoint that never reads, while a socketcand client floods the bus."""
    with TempDir() as tmp:
        server = CanServer(motwin, os.path.join(tmp, "state"), node_id=CAN_NODE,
                           can=("socketcand:127.0.0.1:0", "slcan-tcp:127.0.0.1:0"))
        with server:
            ports = {"socketcand": server.can_port, "slcan": server.slcan_port}
            sleepy_socketcand = socketcand_client(ports["socketcand"], rcvbuf=4096)
            sleepy_slcan = slcan_client(ports["slcan"], rcvbuf=4096)
            flooder = socketcand_client(ports["socketcand"])
            try:
                element = b"< send 123 8 01 02 03 04 05 06 07 08 >"
                batch = element * 1000
                for _ in range(FLOOD_FRAMES // 1000):
                    flooder.send(batch)
                # The flooder never gets its own frames back; it is still served.
                flooder.send(sdo_element(UPLOAD_1000))
                check_equal(sdo_answer_data(flooder.read_until(is_sdo_answer, timeout=30.0)), ANSWER_1000,
                            "flooder's SDO upload after the flood")
                for name, sleepy in (("socketcand", sleepy_socketcand), ("slcan", sleepy_slcan)):
                    received = sleepy.read_to_eof(15.0)
                    check(received is not None, f"never-reading {name} client still connected after the flood")
                    print(f"  never-reading {name} client disconnected after {received} bytes reached it", flush=True)
            finally:
                for c in (sleepy_socketcand, sleepy_slcan, flooder):
                    c.close()
            fresh = slcan_client(ports["slcan"])
            try:
                fresh.send(SLCAN_UPLOAD_1000 + "\r")
                fresh.read_until(lambda u: u == SLCAN_ANSWER_1000, what="SLCAN SDO answer after the flood")
            finally:
                fresh.close()
            check(server.alive(), "server died")
            server.stop()


if __name__ == "__main__":
    run_tests([test_tcp_garbage_clients, test_many_idle_connections, test_pty_resync_by_pause,
               test_can_endpoint_garbage_clients, test_can_never_reading_clients_are_dropped])
