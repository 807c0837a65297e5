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
(resync by pause); garbage without a pause costs at most one checksum-error reply. Frames
written a byte at a time with pauses shorter than the 5 ms resync gap are answered correctly.

The TMCM-142's ASCII interface over TCP, while a well-behaved binary client loops SGP/GGP/GAP:
64 KiB of lines for no module (ignored: no reply), bad and overlong lines for this module (one
reply line each with the documented status), a line typed a byte every 10 ms, clients that
switch to ASCII and disconnect in the middle of a line (the half line never runs), a client that
floods lines and never reads (back-pressure or disconnect).

On a TMCM-3216's CAN endpoints (socketcand and SLCAN over TCP), while a well-behaved socketcand
client loops SDO downloads and uploads and checks every answer (it is the node's only SDO
client, as CANopen requires): 64 KiB of random bytes, then a good command is served (resync at
the next element or CR); elements and command lines typed a byte every 10 ms (slowloris) are
served; half elements and half lines followed by a disconnect;
50 connect/drop (some with a reset); an overlong SLCAN line costs exactly one BEL; a client on
each endpoint that never reads while another floods the bus with 150 000 frames is disconnected
(its unread output is bounded) and the others keep working.

TMCL over CAN (a TMCM-1636, request ID 1, reply ID 2) from a socketcand client: frames shorter
than 7 bytes get the documented status-2 reply, extended ID 1 is answered on extended ID 2,
other IDs and malformed `send` elements get no reply (an `< error >` for the latter), an SLCAN
remote frame on ID 1 none either; a good request after each is answered.
"""

import os
import random
import socket
import struct
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from can_bus_harness import BusServer  # noqa: E402
from canopen_harness import CanServer  # noqa: E402
from client_harness import (  # noqa: E402
    ANSWER_1000, UPLOAD_1000, UnitSocket, Worker, is_slcan_frame, run_beside, sdo_1017_round, sdo_answer_data,
    sdo_answer_of, sdo_element, send_element, slcan_answer, slcan_client, slcan_line, socketcand_client,
    socketcand_frame,
)
from motwin_harness import (  # noqa: E402
    BANK_USER, GAP, GGP, SAP, SGP, STATUS_OK, Server, TcpClient, TempDir, check, check_equal, expect_reply, frame,
    parse_reply, run_tests,
)

CHECKSUM_ERROR_REPLY = bytes.fromhex("02 01 01 00 00 00 00 00 04")
TCP_RESYNC_PAUSE = 0.5  # 5 x the server's TCP resync gap (100 ms, src/host/tcp_server.h): room for a stall
SERIAL_RESYNC_GAP = 0.005  # a pause this long between two bytes drops a partial frame (core/tmcl/serial_link.h)
# A pause meant to resync the serial link, once the server has read what came before: it counts
# only the silence its polls saw (src/host/event_loop.h), so a poll must start at least 5 ms after
# the read. 40 x the gap: room for a server descheduled on a loaded machine.
PTY_RESYNC_PAUSE = 0.2
ENTER_ASCII = 139


def random_garbage(rng, length):
    """Random bytes in which no byte is 0x01, so no alignment ever yields a frame for module 1."""
    return bytes(b if b != 1 else 0 for b in (rng.randrange(256) for _ in range(length)))


def random_bytes_client(port):
    rng = random.Random(7)
    with TcpClient(port) as c:
        for _ in range(16):
            c.send_raw(random_garbage(rng, 4096))
        data = c.read_available(0.5)
        check(data == b"", f"random bytes (no frame for module 1) got an answer: {data[:32].hex(' ')}")
        # The pause counts from the last byte the server read (src/host/event_loop.h): a loaded
        # server may still be reading the garbage long after it was sent.
        c.wait_until_server_read_everything()
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


def connect_and_drop(port, count, first_bytes, every=5):
    """`count` connections closed at once (every third with a reset); every `every`th sends
    first_bytes(i) first."""
    for i in range(count):
        s = socket.create_connection(("127.0.0.1", port), timeout=5.0)
        if i % 3 == 0:
            s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))  # RST on close
        if i % every == 0:
            s.sendall(first_bytes(i))
        s.close()


def connect_and_drop_clients(port):
    connect_and_drop(port, 50, lambda i: b"\x01")
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


def never_reading(port, first, chunk):
    """Sends `first`, then `chunk` over and over without ever reading; the server must push back
    (stop reading) or disconnect. Returns a note."""
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)  # fill up quickly
    s.settimeout(5.0)
    s.connect(("127.0.0.1", port))
    s.sendall(first)
    s.setblocking(False)
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


def never_reading_client(port):
    return never_reading(port, b"", frame(GAP, 44) * 1000)


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
                slowest = [0.0]

                def good_round(i):
                    slowest[0] = max(slowest[0], good_client_round(good, i))

                rounds = run_beside([Worker(w, server.tcp_port) for w in WORKERS], good_round, min_rounds=50,
                                    timeout=60.0, what="garbage clients")
                print(f"  well-behaved client: {rounds} rounds of 5 requests, slowest round {slowest[0] * 1000:.1f} ms",
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
                    read_before = server.bytes_read()
                    c.send_raw(garbage)
                    server.wait_until_read(read_before + len(garbage))
                    time.sleep(PTY_RESYNC_PAUSE)
                    c.expect_no_reply(0.05, f"{name}")
                    expect_reply(c.request(GAP, 43), GAP, STATUS_OK, 3210, f"GAP 43 after {name} and a pause")
                    c.expect_no_reply(0.05, f"after the reply ({name})")
                # No pause: 7 bytes of a frame for module 1 run into the good frame; that costs one
                # checksum-error reply (9 bytes), the rest is dropped by the next pause.
                misaligned = frame(SAP, 43, 0, 9999)[:7] + frame(GAP, 43)
                read_before = server.bytes_read()
                c.send_raw(misaligned)
                check_equal(c.read_exact(9), CHECKSUM_ERROR_REPLY, "misaligned frame")
                server.wait_until_read(read_before + len(misaligned))
                time.sleep(PTY_RESYNC_PAUSE)
                c.expect_no_reply(0.05, "after the misaligned frame")
                expect_reply(c.request(GAP, 43), GAP, STATUS_OK, 3210, "GAP 43 after resync")
            server.stop()


def send_byte_by_byte(client, data, pause):
    """Writes `data` one byte at a time with `pause` after each; returns the longest time between
    two writes as this process saw it (a loaded machine may stall it for longer than asked)."""
    longest = 0.0
    last = None
    for byte in data:
        now = time.monotonic()
        if last is not None:
            longest = max(longest, now - last)
        last = now
        client.send_raw(bytes([byte]))
        time.sleep(pause)
    return longest


def test_pty_slow_writer(motwin):
    """Frames split into single bytes 1 ms apart (the serial resync gap is 5 ms) are answered
    correctly. Should this process itself stall for most of the gap between two bytes, the
    server may rightly drop the partial frame: then the reply is the right one or none at all,
    and the frame is sent again."""
    with TempDir() as tmp:
        link = os.path.join(tmp, "tmcm1636")
        with Server(motwin, os.path.join(tmp, "state"), tcp=False, pty_link=link) as server:
            with server.serial() as c:
                resent = 0
                longest_gap = 0.0
                for i in range(8):
                    value = -70000 - i
                    write = i % 2 == 0
                    request = frame(SGP, 202, BANK_USER, value) if write else frame(GGP, 202, BANK_USER)
                    expected_value = value if write else value + 1
                    what = f"{'SGP' if write else 'GGP'} 202 byte by byte ({i})"
                    for attempt in range(20):
                        gap = send_byte_by_byte(c, request, 0.001)
                        longest_gap = max(longest_gap, gap)
                        if gap < SERIAL_RESYNC_GAP * 0.8:
                            reply = parse_reply(c.read_exact(9, 5.0))
                            expect_reply(reply, request[1], STATUS_OK, expected_value, what)
                            break
                        data = c.read_available(0.1)  # also a pause: what is left of the frame is dropped
                        if data:
                            expect_reply(parse_reply(data), request[1], STATUS_OK, expected_value,
                                         f"{what} after a stall of {gap * 1000:.1f} ms")
                        resent += 1
                    else:
                        raise AssertionError(f"{what}: this process stalled at every attempt")
                c.expect_no_reply(0.05, "after the slow frames")
                expect_reply(c.request(GGP, 202, BANK_USER), GGP, STATUS_OK, -70006, "GGP 202 at full speed")
                print(f"  8 frames byte by byte, longest gap between two writes {longest_gap * 1000:.1f} ms, "
                      f"{resent} sent again after a stall of this process", flush=True)
            server.stop()


# --- The TMCM-142's ASCII interface over TCP --------------------------------------------------

TMCM142_AP4_DEFAULT = 13743895  # AP 4 at the factory (docs/tmcm-142.md)
ASCII_NOT_OURS_FIRST = bytes(b for b in range(256) if b not in b"Aa\r\n\b\x7f\t ")


def tmcm142_ascii_client(port):
    """A TCP client switched to ASCII mode (command 139, binary reply first)."""
    c = TcpClient(port)
    expect_reply(c.request(ENTER_ASCII), ENTER_ASCII, STATUS_OK, 0, "139 (enter ASCII mode)")
    return c


def ascii_exchange(c, line, expected, what):
    """Sends `line`; its answer (GP 67 = 32: no echo) must be exactly `expected`, and nothing after it."""
    c.send_raw(line.encode("latin-1") if isinstance(line, str) else line)
    check_equal(c.read_exact(len(expected), 10.0).decode("latin-1"), expected, what)
    stray = c.read_available(0.02)
    check(stray == b"", f"{what}: unexpected bytes after the answer: {stray!r}")


def ascii_garbage_client(port):
    rng = random.Random(142)
    lines = []
    size = 0
    while size < 65536:  # lines whose first byte is no module's letter: ignored to their end
        body = bytes(b for b in (rng.randrange(256) for _ in range(rng.randrange(300))) if b not in b"\r\n")
        lines.append(bytes([rng.choice(ASCII_NOT_OURS_FIRST)]) + body + b"\r")
        size += len(lines[-1])
    with tmcm142_ascii_client(port) as c:
        c.send_raw(b"".join(lines))
        data = c.read_available(0.5)
        check(data == b"", f"{len(lines)} lines for no module got an answer: {data[:40]!r}")
        for line, expected, what in [
            ("AFOO 1, 2\r", "BA 2 0\r", "unknown word"),
            ("A\x01\xff\x1b[2J\r", "BA 2 0\r", "control and 8-bit bytes"),
            ("AGAP 4\r", "BA 4 0\r", "missing operand"),
            ("AGAP 4,, 0\r", "BA 4 0\r", "empty operand"),
            ("ASAP 4, 0, 99999999999\r", "BA 4 0\r", "value beyond 32 bits"),
            ("A" + "X" * 100_000 + "\r", "BA 2 0\r", "a line of 100 000 characters"),
            ("AGAP 4, 0\r", f"BA 100 {TMCM142_AP4_DEFAULT}\r", "a good line after all that"),
        ]:
            ascii_exchange(c, line, expected, what)
    return f"{size} bytes in {len(lines)} lines for no module (no answer), 6 bad lines answered, then a good one"


def ascii_slow_client(port):
    with tmcm142_ascii_client(port) as c:
        c.send_raw(b"A")
        for byte in b"GAP 4, 0":
            time.sleep(0.01)
            c.send_raw(bytes([byte]))
        check_equal(c.read_available(0.05), b"", "answer before the CR")
        ascii_exchange(c, "\r", f"BA 100 {TMCM142_AP4_DEFAULT}\r", "a line typed a byte every 10 ms")
    return "a line typed a byte every 10 ms answered"


def ascii_half_line_clients(port):
    enter = frame(ENTER_ASCII)
    connect_and_drop(port, 20, lambda i: enter + b"ASGP 50, 2, 666"[:4 + i % 12], every=1)  # in one write
    for i in range(10):
        with tmcm142_ascii_client(port) as c:
            c.send_raw(b"ASAP 4, 0, 12"[: 3 + i])
    return "30 connections left in the middle of an ASCII line"


def ascii_never_reading_client(port):
    return never_reading(port, frame(ENTER_ASCII), b"AGAP 4, 0\r" * 1000)


def test_tmcm142_ascii_tcp_misbehaving_clients(motwin):
    with TempDir() as tmp:
        args = ["--module", "tmcm-142", "--tmcl-tcp", "127.0.0.1:0"]
        with BusServer(motwin, os.path.join(tmp, "state"), args) as server:
            port = server.tcp_port_of()
            good = TcpClient(port)
            try:
                good.sgp(67, 0, 32)  # ASCII replies without echo, so that every byte is predictable

                def good_round(i):
                    value = 1000 + i
                    expect_reply(good.request(SGP, 9, BANK_USER, value), SGP, STATUS_OK, value, "good SGP uv 9")
                    expect_reply(good.request(GGP, 9, BANK_USER), GGP, STATUS_OK, value, "good GGP uv 9")
                    expect_reply(good.request(GAP, 4), GAP, STATUS_OK, TMCM142_AP4_DEFAULT, "good GAP 4")

                workers = [Worker(w, port) for w in (ascii_garbage_client, ascii_slow_client, ascii_half_line_clients,
                                                     ascii_never_reading_client)]
                rounds = run_beside(workers, good_round, min_rounds=30, timeout=60.0, what="ASCII clients")
                print(f"  well-behaved binary client: {rounds} rounds of 3 requests", flush=True)
                check_equal(good.ggp(50, BANK_USER), 0, "user variable 50 after the half lines")
                check_equal(good.gap(4), TMCM142_AP4_DEFAULT, "AP 4 after the half lines")
            finally:
                good.close()
            check(server.alive(), "server died")
            with TcpClient(port) as c:  # a new connection starts in binary mode (GP 67 bit 0 clear)
                check_equal(c.version_string(), b"142V1.06", "version afterwards")
            server.stop()


# --- CAN endpoints: socketcand and SLCAN over TCP -----------------------------------------------

CAN_NODE = 5
SLCAN_DATA_FRAME_BYTES = len("t12380102030405060708\r")
SERVER_MAX_PENDING_OUTPUT = 1024 * 1024  # kMaxPendingOutputBytes of src/host/slcan_server.h and socketcand_server.h


def kernel_send_buffer_limit():
    """The most the kernel may buffer for one TCP sender (autotuning stops at tcp_wmem's maximum)."""
    try:
        with open("/proc/sys/net/ipv4/tcp_wmem") as f:
            return int(f.read().split()[2])
    except (OSError, ValueError, IndexError):
        return 4 * 1024 * 1024


def frames_to_overflow_a_never_reading_client():
    """A flood big enough that a never-reading SLCAN client's output passes the server's limit even
    when the kernel has taken all it may into the socket buffers (the shortest line is SLCAN's)."""
    worst_case_bytes = kernel_send_buffer_limit() + SERVER_MAX_PENDING_OUTPUT + 64 * 1024
    return (worst_case_bytes * 5 // 4) // SLCAN_DATA_FRAME_BYTES // 1000 * 1000 + 1000


FLOOD_FRAMES = frames_to_overflow_a_never_reading_client()
SLCAN_UPLOAD_1000 = slcan_line(0x600 + CAN_NODE, UPLOAD_1000)
SLCAN_ANSWER_1000 = slcan_line(0x580 + CAN_NODE, ANSWER_1000) + "\r"


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
    c = UnitSocket(ports["socketcand"], (b">",))
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
    connect_and_drop(ports["socketcand"], 25, lambda i: b"< send 605 8 40")
    connect_and_drop(ports["slcan"], 25, lambda i: b"t6058400")
    return "50 half elements/lines and connect/drop"


def test_can_endpoint_garbage_clients(motwin):
    with TempDir() as tmp:
        server = CanServer(motwin, os.path.join(tmp, "state"), node_id=CAN_NODE,
                           can=("socketcand:127.0.0.1:0", "slcan-tcp:127.0.0.1:0"))
        with server:
            ports = {"socketcand": server.can_port, "slcan": server.slcan_port}
            good = socketcand_client(ports["socketcand"])
            try:
                workers = [Worker(w, ports) for w in
                           (can_garbage_socketcand, can_garbage_slcan, can_slowloris, can_half_and_drop)]
                rounds = run_beside(workers, lambda i: sdo_1017_round(good, CAN_NODE, i), min_rounds=30, timeout=60.0,
                                    what="CAN garbage clients")
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
                flooder.send(sdo_element(CAN_NODE, UPLOAD_1000))
                check_equal(sdo_answer_data(flooder.read_until(sdo_answer_of(CAN_NODE), timeout=30.0)), ANSWER_1000,
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


# --- TMCL over CAN: malformed frames ------------------------------------------------------------

TMCL_RECEIVE_ID, TMCL_SEND_ID = 1, 2
GGP71 = [GGP, 71, 0, 0, 0, 0, 0]                     # GGP 71 (receive ID), bank 0: value 1
GGP71_REPLY = bytes([1, STATUS_OK, GGP, 0, 0, 0, 1])  # receive ID, status, command, value


def tmcl_can_units(c, element):
    """Sends `element` and then a good GGP 71 request; returns the error elements, the replies
    on the send ID (ID, extended, data) up to and including the good request's, in order."""
    c.send(element)
    c.send(send_element(TMCL_RECEIVE_ID, GGP71))
    errors, replies = [], []
    while True:
        unit = c.read_unit(10.0)
        if "error" in unit:
            errors.append(unit.strip())
            continue
        frame_ = socketcand_frame(unit)
        if frame_ is None or frame_[0] != TMCL_SEND_ID:
            continue
        replies.append(frame_)
        if frame_ == (TMCL_SEND_ID, False, GGP71_REPLY):
            return errors, replies


def status_2(command, length=7, extended=False):
    """The reply to a frame too short for a request: status 2, its command byte, value 0."""
    return [(TMCL_SEND_ID, extended, bytes([TMCL_RECEIVE_ID, 2, command]) + bytes(length - 3))]


def test_tmcl_over_can_malformed_frames(motwin):
    good_reply = [(TMCL_SEND_ID, False, GGP71_REPLY)]
    cases = [  # (what, element, socketcand errors, replies before the good request's)
        ("empty frame", send_element(1, []), 0, status_2(0)),
        ("2 bytes", send_element(1, [SGP, 3]), 0, status_2(SGP)),
        ("6 bytes", send_element(1, [SGP, 3, 2, 0, 0, 7]), 0, status_2(SGP)),
        ("extended ID 1, 7 bytes", send_element(1, [GGP, 70, 0, 0, 0, 0, 0], extended=True), 0,
         [(TMCL_SEND_ID, True, bytes([1, STATUS_OK, GGP, 0, 0, 0, 2]))]),
        ("extended ID 1, 3 bytes", send_element(1, [GGP, 70, 0], extended=True), 0, status_2(GGP, extended=True)),
        ("8 bytes, a wrong 8th byte (not checked)", send_element(1, [GGP, 70, 0, 0, 0, 0, 0, 0x55]), 0,
         [(TMCL_SEND_ID, False, bytes([1, STATUS_OK, GGP, 0, 0, 0, 2, 0]))]),
        ("extended ID 0x10000001", send_element(0x10000001, GGP71, extended=True), 0, []),
        ("standard ID 0x101", send_element(0x101, GGP71), 0, []),
        ("ID 0x800 (extended by its value)", send_element(0x800, GGP71), 0, []),
        ("length 9", "< send 1 9 0A 47 00 00 00 00 00 00 00 >", 1, []),
        ("length 7, 2 bytes", "< send 1 7 0A 47 >", 1, []),
        ("bad data byte", "< send 1 7 0A 47 00 00 00 00 XYZ >", 1, []),
        ("9-digit ID", "< send 100000001 7 0A 47 00 00 00 00 00 >", 1, []),
        ("no length", "< send 1 >", 1, []),
        ("unknown command", "< sned 1 7 0A 47 00 00 00 00 00 >", 1, []),
    ]
    with TempDir() as tmp:
        args = ["--module", "tmcm-1636", "--can", "socketcand:127.0.0.1:0", "--can", "slcan-tcp:127.0.0.1:0"]
        with BusServer(motwin, os.path.join(tmp, "state"), args) as server:
            c = socketcand_client(server.port())
            try:
                for what, element, error_count, replies in cases:
                    errors, got = tmcl_can_units(c, element)
                    check_equal(len(errors), error_count, f"{what}: socketcand errors {errors}")
                    check_equal(got, replies + good_reply, f"{what}: replies on ID 2")
                # A remote frame on ID 1 over SLCAN: acknowledged by the adapter, not answered by the module.
                s = slcan_client(server.port("can-slcan-tcp"))
                try:
                    for line in ("r0017", "R000000017"):
                        s.send(line + "\r")
                        check_equal(slcan_answer(s), "Z\r" if line[0] == "R" else "z\r", f"{line} acknowledged")
                    s.send(slcan_line(TMCL_RECEIVE_ID, GGP71) + "\r")
                    check_equal(slcan_answer(s), "z\r", "good request acknowledged")
                    reply = s.read_until(is_slcan_frame, what="TMCL reply over SLCAN")
                    check_equal(reply, slcan_line(TMCL_SEND_ID, GGP71_REPLY) + "\r", "first frame after the RTRs")
                finally:
                    s.close()
                c.read_until(lambda u: socketcand_frame(u) == good_reply[0], timeout=10.0,
                             what="the reply to the SLCAN client's request, seen on socketcand")
                errors, got = tmcl_can_units(c, "< echo >")
                check_equal((errors, got), ([], good_reply), "a good request at the end")
            finally:
                c.close()
            check(server.alive(), "server died")
            server.stop()


if __name__ == "__main__":
    run_tests([test_tcp_garbage_clients, test_many_idle_connections, test_pty_resync_by_pause, test_pty_slow_writer,
               test_tmcm142_ascii_tcp_misbehaving_clients, test_can_endpoint_garbage_clients,
               test_can_never_reading_clients_are_dropped, test_tmcl_over_can_malformed_frames])
