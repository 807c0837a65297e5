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
- socketcand flood: 20 000 frames on the bus from one client (100 batches of 200, 10 ms apart:
  at most 20 000 per second) while another, reading everything the bus passes on, makes SDO
  transfers.
- SLCAN over TCP flood: the same 20 000 frames from an SLCAN adapter client, which gets exactly
  20 000 acknowledgements (`z`), then has an SDO upload answered itself.
- socketcand connections: 64 clients in raw mode at once (the server's limit), a frame from one
  reaching the 63 others; a 65th is accepted and closed at once (no greeting) and logged; once
  one client leaves, a new one is greeted at once; after all have gone the server holds as many
  descriptors as before.

The SLCAN adapter on a pseudo-terminal is flooded in test_slcan_clients.py.
"""

import os
import socket
import sys
import threading
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import CanServer  # noqa: E402
from client_harness import (  # noqa: E402
    ANSWER_1000, UPLOAD_1000, Memory, UnitSocket, Worker, check_descriptors_return, open_descriptors,
    run_beside, sdo_1017_round, sdo_answer_data, sdo_answer_of, sdo_element, send_element, slcan_answer, slcan_client,
    slcan_line, socketcand_client, socketcand_frame, write_and_read_some,
)
from motwin_harness import (  # noqa: E402
    BANK_USER, GAP, GGP, SGP, STATUS_OK, Server, TcpClient, TempDir, check, check_equal, expect_reply, frame,
    parse_reply, run_tests,
)

CAN_NODE = 5


def good_round(c, i):
    value = 1000 + i
    expect_reply(c.request(SGP, 9, BANK_USER, value), SGP, STATUS_OK, value, "good SGP uv9")
    expect_reply(c.request(GGP, 9, BANK_USER), GGP, STATUS_OK, value, "good GGP uv9")
    expect_reply(c.request(GAP, 43), GAP, STATUS_OK, 4000, "good GAP 43")


def run_with_good_client(load, good_rounds, memory, min_rounds=20):
    """Runs `load` in a thread while this one runs good_rounds(i), sampling the RSS."""
    return run_beside([Worker(load)], good_rounds, min_rounds=min_rounds, timeout=120.0, on_round=memory.sample,
                      what="load")


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

                rounds = run_with_good_client(open_200, lambda i: good_round(good, i), memory)
                print(f"  well-behaved client: {rounds} rounds", flush=True)
                for s in held[:20]:  # the first ones are served
                    c = TcpClient.from_socket(s)
                    expect_reply(c.request(GAP, 43), GAP, STATUS_OK, 4000, "GAP on a held connection")
            finally:
                for s in held:
                    s.close()
            memory.check("200 connections")

            # The server notices the closed sockets on its own schedule; then cycles.
            check_descriptors_return(server.proc.pid, descriptors_before, "after the 200 connections closed")
            for i in range(200):
                with server.tcp() as c:
                    expect_reply(c.request(SGP, 10, BANK_USER, i), SGP, STATUS_OK, i, f"cycle {i}")
            check_descriptors_return(server.proc.pid, descriptors_before, "after 400 connections")

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

                rounds = run_with_good_client(flood_body, lambda i: good_round(good, i), memory)
                print(f"  well-behaved client: {rounds} rounds meanwhile", flush=True)
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
                                pending, received = write_and_read_some(fd, pending)
                                data += received
                        finally:
                            os.set_blocking(fd, True)
                        check(len(data) == 9 * count, f"pty flood: {len(data)} of {9 * count} reply bytes in 120 s")
                        replies = [parse_reply(data[i:i + 9]) for i in range(0, len(data), 9)]
                        for r in replies:
                            check((r.status, r.command) == (STATUS_OK, GGP), f"pty flood reply {r.raw.hex(' ')}")
                        c.expect_no_reply(0.2, "after the pty flood")
                        return f"{count} frames written in 4 KiB pieces, {len(replies)} replies"

                    rounds = run_with_good_client(pty_flood, lambda i: good_round(good, i), memory)
                    print(f"  well-behaved TCP client: {rounds} rounds meanwhile", flush=True)
                    expect_reply(c.request(GAP, 43), GAP, STATUS_OK, 4000, "pty GAP after the flood")
            finally:
                good.close()
            memory.check("pty flood")
            server.stop()


# --- CAN endpoints ------------------------------------------------------------------------------

FLOOD_ELEMENT = "< send 123 8 01 02 03 04 05 06 07 08 >"
FLOOD_BATCHES, FLOOD_BATCH = 100, 200


def can_flood_beside_sdo_client(server, flooder, batch, memory):
    """Sends FLOOD_BATCHES x `batch` (FLOOD_BATCH frames) from `flooder`, 10 ms apart, while a
    socketcand client on the same server makes SDO rounds and reads everything the bus passes on."""
    good = socketcand_client(server.can_port)
    try:
        def flood():
            # 20 000 frames per second at most: more than twice what a 1 Mbit/s bus carries.
            # Every client receives the flood too; a client that cannot keep up is cut off at
            # the server's output limit (by design), so the rate stays within what a Python
            # reader on a loaded CI machine drains.
            for _ in range(FLOOD_BATCHES):
                flooder.send(batch)
                time.sleep(0.01)
            return f"{FLOOD_BATCHES * FLOOD_BATCH} frames sent"

        rounds = run_with_good_client(flood, lambda i: sdo_1017_round(good, CAN_NODE, i), memory)
        print(f"  well-behaved SDO client: {rounds} rounds meanwhile", flush=True)
    finally:
        good.close()


def test_socketcand_frame_flood(motwin):
    with TempDir() as tmp:
        server = CanServer(motwin, os.path.join(tmp, "state"), node_id=CAN_NODE)
        with server:
            memory = Memory(server.proc.pid)
            flooder = socketcand_client(server.can_port)
            try:
                can_flood_beside_sdo_client(server, flooder, FLOOD_ELEMENT * FLOOD_BATCH, memory)
                # The flooder never gets its own frames back; it is still served.
                flooder.send(sdo_element(CAN_NODE, UPLOAD_1000))
                check_equal(sdo_answer_data(flooder.read_until(sdo_answer_of(CAN_NODE, 0x1000), timeout=10.0)),
                            ANSWER_1000, "flooder's SDO upload after the flood")
            finally:
                flooder.close()
            memory.check("socketcand flood")
            server.stop()


def test_slcan_tcp_frame_flood(motwin):
    with TempDir() as tmp:
        server = CanServer(motwin, os.path.join(tmp, "state"), node_id=CAN_NODE,
                           can=("socketcand:127.0.0.1:0", "slcan-tcp:127.0.0.1:0"))
        with server:
            memory = Memory(server.proc.pid)
            flooder = slcan_client(server.slcan_port)
            try:
                batch = (slcan_line(0x123, bytes(range(1, 9))) + "\r") * FLOOD_BATCH
                can_flood_beside_sdo_client(server, flooder, batch, memory)
                # Read only now: every frame was acknowledged, in between the bus's frames (the
                # SDO rounds, the heartbeats they set).
                acks = 0
                while acks < FLOOD_BATCHES * FLOOD_BATCH:
                    answer = slcan_answer(flooder)
                    check_equal(answer, "z\r", f"SLCAN answer after {acks} acknowledgements")
                    acks += 1
                flooder.send(slcan_line(0x600 + CAN_NODE, UPLOAD_1000) + "\r")
                check_equal(slcan_answer(flooder), "z\r", "the flooder's SDO upload acknowledged")
                flooder.read_until(lambda u: u == slcan_line(0x580 + CAN_NODE, ANSWER_1000) + "\r", timeout=10.0,
                                   what="the flooder's SDO answer")
                print(f"  SLCAN flooder: {acks} acknowledgements, then its SDO upload answered", flush=True)
            finally:
                flooder.close()
            memory.check("SLCAN over TCP flood")
            server.stop()


SOCKETCAND_MAX_CLIENTS = 64  # SocketcandServer::kMaxClients


def test_socketcand_many_connections(motwin):
    with TempDir() as tmp:
        server = CanServer(motwin, os.path.join(tmp, "state"), node_id=CAN_NODE)
        with server:
            pid = server.proc.pid
            memory = Memory(pid)
            descriptors_before = open_descriptors(pid)
            clients = []
            try:
                for _ in range(SOCKETCAND_MAX_CLIENTS):
                    clients.append(socketcand_client(server.can_port))
                    time.sleep(0.002)  # the listen backlog is 16: no SYN retransmissions
                # One more is accepted and closed at once, without a greeting.
                extra = UnitSocket(server.can_port, (b">",))
                try:
                    check_equal(extra.read_to_eof(10.0), 0, "bytes the 65th socketcand client got before the close")
                finally:
                    extra.close()
                refused = [line for line in server.stderr_lines() if "refusing socketcand client" in line]
                check_equal(len(refused), 1, "log lines about a refused client")
                # Every client is served: a frame from the first reaches all the others.
                clients[0].send(send_element(0x123, [0xAA, 0x55]))
                for n, c in enumerate(clients[1:], start=1):
                    c.read_until(lambda u: socketcand_frame(u) == (0x123, False, b"\xAA\x55"), timeout=10.0,
                                 what=f"the first client's frame at client {n}")
                sdo_1017_round(clients[-1], CAN_NODE, 1)
                # A freed slot is taken at once.
                clients.pop(0).close()
                clients.append(socketcand_client(server.can_port))
                sdo_1017_round(clients[-1], CAN_NODE, 2)
                print(f"  {SOCKETCAND_MAX_CLIENTS} clients served, the next refused: {refused[0]}", flush=True)
            finally:
                for c in clients:
                    c.close()
            check_descriptors_return(pid, descriptors_before, "after 66 socketcand connections")
            memory.check("socketcand connections")
            server.stop()


if __name__ == "__main__":
    run_tests([test_many_tcp_connections, test_tcp_frame_flood, test_pty_frame_flood, test_socketcand_frame_flood,
               test_slcan_tcp_frame_flood, test_socketcand_many_connections])
