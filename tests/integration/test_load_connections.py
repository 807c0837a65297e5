#!/usr/bin/python3
"""Load: many connections and frame floods within fixed bounds of memory and time.

Bounds are generous and not about speed: the server's resident memory (VmRSS from /proc) may
grow by at most 48 MiB over its idle figure (256 MiB under AddressSanitizer, whose quarantine
holds freed memory), and a well-behaved client keeps getting correct answers, each within the
harness's 2 s reply timeout, while the load runs.

- TCP: 200 connections held open at once (the server serves 64 at a time; the rest wait in the
  listen queue) while the well-behaved client works; then 200 connect / request / close cycles
  in a row, each answered correctly, leaving the server with as many open descriptors as before;
  48 clients at once, each writing and reading back its own user variable 30 times.
- TCP flood: one client pipelines 100 000 GAP frames without waiting and reads the replies as they
  come: exactly 100 000 correct replies, in order.
- pty flood: 5 000 frames written at once to the pseudo-terminal: 5 000 correct replies.
- socketcand flood: 100 000 frames on the bus from one client (at most 200 000 per second) while
  another, reading everything the bus passes on, makes SDO transfers.
"""

import os
import select
import socket
import struct
import sys
import threading
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import CanServer  # noqa: E402
from motwin_harness import (  # noqa: E402
    BANK_USER, GAP, GGP, SGP, STATUS_OK, Server, TcpClient, TempDir, check, check_equal, expect_reply, frame,
    parse_reply, run_tests,
)
from test_garbage_clients import (  # noqa: E402
    CAN_NODE, is_sdo_answer, sdo_answer_data, sdo_element, socketcand_client,
)

MIB = 1024 * 1024
RSS_GROWTH_LIMIT = 48 * MIB
RSS_GROWTH_LIMIT_ASAN = 256 * MIB


class Memory:
    """VmRSS of the server, sampled by the test while the load runs."""

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


def good_round(c, i):
    value = 1000 + i
    expect_reply(c.request(SGP, 9, BANK_USER, value), SGP, STATUS_OK, value, "good SGP uv9")
    expect_reply(c.request(GGP, 9, BANK_USER), GGP, STATUS_OK, value, "good GGP uv9")
    expect_reply(c.request(GAP, 43), GAP, STATUS_OK, 4000, "good GAP 43")


class Load(threading.Thread):
    def __init__(self, body):
        super().__init__(daemon=True)
        self.body = body
        self.failure = None
        self.note = ""

    def run(self):
        try:
            self.note = self.body() or ""
        except Exception as error:  # noqa: BLE001 - reported by the main thread
            self.failure = repr(error)


def run_with_good_client(load, good_rounds, memory, min_rounds=20):
    """Runs `load` in a thread while the main thread runs good_rounds(i); samples the RSS."""
    worker = Load(load)
    worker.start()
    rounds = 0
    deadline = time.monotonic() + 120.0
    while worker.is_alive() or rounds < min_rounds:
        check(time.monotonic() < deadline, "load still running after 120 s")
        good_rounds(rounds)
        memory.sample()
        rounds += 1
    worker.join()
    check(worker.failure is None, f"load failed: {worker.failure}")
    return rounds, worker.note


# --- TCP ------------------------------------------------------------------------------------------

def test_many_tcp_connections(motwin):
    with TempDir() as tmp:
        with Server(motwin, os.path.join(tmp, "state")) as server:
            memory = Memory(server.proc.pid)
            good = server.tcp()
            good_round(good, 0)  # accepted by now: counted in the descriptors before
            descriptors_before = open_descriptors(server.proc.pid)
            held = []
            try:
                def open_200():
                    for _ in range(200):
                        held.append(socket.create_connection(("127.0.0.1", server.tcp_port), timeout=30.0))
                        time.sleep(0.002)  # the listen backlog is 16: no SYN retransmissions
                    return "200 connections open"

                rounds, note = run_with_good_client(open_200, lambda i: good_round(good, i), memory)
                print(f"  {note}; well-behaved client: {rounds} rounds", flush=True)
                for s in held[:20]:  # the first ones are served
                    c = TcpClient.from_socket(s)
                    expect_reply(c.request(GAP, 43), GAP, STATUS_OK, 4000, "GAP on a held connection")
            finally:
                for s in held:
                    s.close()
            memory.check("200 connections")

            # The server notices the closed sockets on its own schedule; then cycles.
            time.sleep(0.5)
            for i in range(200):
                with server.tcp() as c:
                    expect_reply(c.request(SGP, 10, BANK_USER, i), SGP, STATUS_OK, i, f"cycle {i}")
            deadline = time.monotonic() + 10.0
            while open_descriptors(server.proc.pid) != descriptors_before and time.monotonic() < deadline:
                time.sleep(0.05)
            check_equal(open_descriptors(server.proc.pid), descriptors_before,
                        f"server descriptors after 400 connections ({descriptor_targets(server.proc.pid)})")

            def client(n, failures):
                try:
                    with server.tcp() as c:
                        for j in range(30):
                            value = n * 1000 + j
                            expect_reply(c.request(SGP, 20 + n, BANK_USER, value), SGP, STATUS_OK, value, "SGP")
                            expect_reply(c.request(GGP, 20 + n, BANK_USER), GGP, STATUS_OK, value, "GGP")
                except Exception as error:  # noqa: BLE001
                    failures.append(f"client {n}: {error!r}")

            failures = []
            threads = [threading.Thread(target=client, args=(n, failures), daemon=True) for n in range(48)]
            for t in threads:
                t.start()
            for t in threads:
                t.join(60.0)
            check(not any(t.is_alive() for t in threads), "concurrent clients did not finish")
            check(not failures, f"concurrent clients: {failures[:3]}")
            good_round(good, 0)
            good.close()
            memory.check("after the concurrent clients")
            server.stop()


def pipelined_flood(sock, count, request, expected_reply):
    """Writes `count` copies of `request` from a thread while reading replies here; returns how
    many replies arrived, after checking each."""
    def writer():
        batch = request * 1000
        for _ in range(count // 1000):
            sock.sendall(batch)

    thread = threading.Thread(target=writer, daemon=True)
    thread.start()
    received = b""
    replies = 0
    deadline = time.monotonic() + 120.0
    while replies < count:
        check(time.monotonic() < deadline, f"flood: {replies} of {count} replies after 120 s")
        sock.settimeout(10.0)
        chunk = sock.recv(1 << 16)
        check(chunk, f"flood: connection closed after {replies} replies")
        received += chunk
        whole = len(received) // 9 * 9
        block = received[:whole]
        check(block == expected_reply * (whole // 9), f"flood: a wrong reply near reply {replies}")
        replies += whole // 9
        received = received[whole:]
    thread.join(10.0)
    return replies


def test_tcp_frame_flood(motwin):
    with TempDir() as tmp:
        with Server(motwin, os.path.join(tmp, "state")) as server:
            memory = Memory(server.proc.pid)
            good = server.tcp()
            flood = socket.create_connection(("127.0.0.1", server.tcp_port), timeout=10.0)
            try:
                expected = bytes.fromhex("02 01 64 06 00 00 0f a0") + bytes([(2 + 1 + 100 + 6 + 0x0f + 0xa0) & 0xFF])
                check_equal(parse_reply(expected).value, 4000, "expected reply")

                def flood_body():
                    n = pipelined_flood(flood, 100_000, frame(GAP, 43), expected)
                    return f"{n} pipelined GAP frames answered in order"

                rounds, note = run_with_good_client(flood_body, lambda i: good_round(good, i), memory)
                print(f"  {note}; well-behaved client: {rounds} rounds meanwhile", flush=True)
            finally:
                flood.close()
                good.close()
            memory.check("TCP flood")
            server.stop()


def test_pty_frame_flood(motwin):
    with TempDir() as tmp:
        link = os.path.join(tmp, "tmcm1636")
        with Server(motwin, os.path.join(tmp, "state"), pty_link=link) as server:
            memory = Memory(server.proc.pid)
            good = server.tcp()
            try:
                with server.serial() as c:
                    count = 5000
                    request = frame(GGP, 9, BANK_USER)

                    def pty_flood():
                        # Write the flood and read the replies in one loop on the raw descriptor,
                        # reading whenever anything is there, as a serial client does: the server
                        # stops reading while its replies back up (back-pressure), so a client that
                        # writes everything before reading (or blocks in a drain) can stall both sides.
                        fd = c.port.fd
                        pending = request * count
                        data = b""
                        deadline = time.monotonic() + 120.0
                        os.set_blocking(fd, False)
                        try:
                            while len(data) < 9 * count and time.monotonic() < deadline:
                                readable, writable, _ = select.select([fd], [fd] if pending else [], [], 1.0)
                                if readable:
                                    data += os.read(fd, 65536)
                                if writable and pending:
                                    try:
                                        pending = pending[os.write(fd, pending[:4096]):]
                                    except BlockingIOError:
                                        pass
                        finally:
                            os.set_blocking(fd, True)
                        check(len(data) == 9 * count, f"pty flood: {len(data)} of {9 * count} reply bytes in 120 s")
                        replies = [parse_reply(data[i:i + 9]) for i in range(0, len(data), 9)]
                        for r in replies:
                            check((r.status, r.command) == (STATUS_OK, GGP), f"pty flood reply {r.raw.hex(' ')}")
                        c.expect_no_reply(0.2, "after the pty flood")
                        return f"{count} frames written in 4 KiB pieces, {len(replies)} replies"

                    rounds, note = run_with_good_client(pty_flood, lambda i: good_round(good, i), memory)
                    print(f"  {note}; well-behaved TCP client: {rounds} rounds meanwhile", flush=True)
                    expect_reply(c.request(GAP, 43), GAP, STATUS_OK, 4000, "pty GAP after the flood")
            finally:
                good.close()
            memory.check("pty flood")
            server.stop()


# --- socketcand ---------------------------------------------------------------------------------

def test_socketcand_frame_flood(motwin):
    with TempDir() as tmp:
        server = CanServer(motwin, os.path.join(tmp, "state"), node_id=CAN_NODE)
        with server:
            memory = Memory(server.proc.pid)
            good = socketcand_client(server.can_port)
            flooder = socketcand_client(server.can_port)
            try:
                def flood():
                    # 20 000 frames per second at most: more than twice what a 1 Mbit/s bus carries.
                    # Every client receives the flood too; a client that cannot keep up is cut off at
                    # the server's output limit (by design), so the rate stays within what a Python
                    # reader on a loaded CI machine drains.
                    batch = b"< send 123 8 01 02 03 04 05 06 07 08 >" * 200
                    for _ in range(100):
                        flooder.send(batch)
                        time.sleep(0.01)
                    return "20 000 frames sent"

                def sdo_round(i):
                    value = 100 + i % 1000
                    good.send(sdo_element([0x2B, 0x17, 0x10, 0, value & 0xFF, value >> 8, 0, 0]))
                    check_equal(sdo_answer_data(good.read_until(is_sdo_answer, timeout=10.0))[:4],
                                bytes([0x60, 0x17, 0x10, 0]), f"1017 = {value}")
                    good.send(sdo_element([0x40, 0x17, 0x10, 0, 0, 0, 0, 0]))
                    answer = sdo_answer_data(good.read_until(is_sdo_answer, timeout=10.0))
                    check_equal(struct.unpack_from("<H", answer, 4)[0], value, "1017 read back")

                rounds, note = run_with_good_client(flood, sdo_round, memory)
                print(f"  {note}; well-behaved SDO client: {rounds} rounds meanwhile", flush=True)
            finally:
                good.close()
                flooder.close()
            memory.check("socketcand flood")
            server.stop()


if __name__ == "__main__":
    run_tests([test_many_tcp_connections, test_tcp_frame_flood, test_pty_frame_flood, test_socketcand_frame_flood])
