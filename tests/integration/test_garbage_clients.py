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

from motwin_harness import (  # noqa: E402
    BANK_USER, GAP, GGP, SAP, SGP, STATUS_OK, Server, TcpClient, TempDir, check, check_equal, expect_reply, frame,
    parse_reply, run_tests,
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
    deadline = time.monotonic() + 8.0
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


if __name__ == "__main__":
    run_tests([test_tcp_garbage_clients, test_many_idle_connections, test_pty_resync_by_pause])
