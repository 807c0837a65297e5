#!/usr/bin/python3
"""One CAN bus across two `motwin serve` processes (`--can socketcand-client:HOST:PORT:CHANNEL`,
docs/canopen.md "A bus across serves and machines"), with Debian's python3-can:
- serve A serves its bus over socketcand with a TMCM-3216 (node 1) and a TMCM-1636 (TMCL over CAN);
  serve B has a TMCM-3216 (node 2), joins A's bus as a socketcand client and serves its own bus
  over socketcand too; a watcher on A and a client on B see every frame of the one bus, once;
- SDO and TMCL across, heartbeats of both sides, a TPDO of node 2 received on A's side;
- start-up errors: no server, a server that refuses the channel, a malformed endpoint;
- the server going away: B logs it, keeps its own bus running and joins again when it is back.
"""

import os
import socket
import struct
import sys
import threading
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from can_bus_harness import BusServer, TmclCan, check, check_equal, collect, collect_through, free_port  # noqa: E402
from canopen_harness import CanopenClient, run_can_tests  # noqa: E402
from motwin_harness import FRAME_TIMEOUT, TempDir, TestFailure  # noqa: E402

DEVICE_TYPE_3216 = 0xFFFF0192
UPLOAD_1000 = [0x40, 0x00, 0x10, 0, 0, 0, 0, 0]


def serve_a(motwin, tmp, port=0):
    args = ["--node", "tmcm-3216:node-id=1", "--node", "tmcm-1636", "--can", f"socketcand:127.0.0.1:{port}"]
    return BusServer(motwin, os.path.join(tmp, "a"), args)


def serve_b(motwin, tmp, port_a):
    args = ["--node", "tmcm-3216:node-id=2", "--can", f"socketcand-client:127.0.0.1:{port_a}:can0",
            "--can", "socketcand:127.0.0.1:0"]
    return BusServer(motwin, os.path.join(tmp, "b"), args)


def frames_of(messages):
    return [(m.arbitration_id, bytes(m.data)) for m in messages]


def wait_for_stderr(server, text, timeout=FRAME_TIMEOUT):
    deadline = time.monotonic() + timeout
    while not any(text in line for line in server.stderr_lines()):
        if time.monotonic() > deadline:
            raise TestFailure(f"no {text!r} on serve's stderr within {timeout} s: {server.stderr_lines()!r}")
        time.sleep(0.01)


def test_two_serves_form_one_bus(motwin):
    with TempDir() as tmp:
        with serve_a(motwin, tmp) as a:
            port_a = a.port()
            with serve_b(motwin, tmp, port_a) as b:
                check_equal(b.endpoints["can-socketcand-client"], [[f"127.0.0.1:{port_a}", "can0"]],
                            "B's endpoint line")
                watcher = CanopenClient(port_a)           # on A's side
                client = CanopenClient(b.port())          # on B's side
                try:
                    # SDO across, both ways, each frame once on each side (no echo, no loop).
                    watcher.drain()
                    client.drain()
                    client.send(0x601, UPLOAD_1000)
                    seen_b = collect_through(client.bus, lambda m: m.arbitration_id in (0x601, 0x581),
                                             lambda m: m.arbitration_id == 0x581)
                    check_equal(frames_of(seen_b), [(0x581, bytes.fromhex("430010009201FFFF"))],
                                "B's client: node 1's answer once, its own request not back")
                    seen_a = collect_through(watcher.bus, lambda m: m.arbitration_id in (0x601, 0x581),
                                             lambda m: m.arbitration_id == 0x581)
                    check_equal(frames_of(seen_a), [(0x601, bytes(UPLOAD_1000)),
                                                    (0x581, bytes.fromhex("430010009201FFFF"))],
                                "A's watcher: B's request and node 1's answer, once each")
                    check_equal(watcher.upload_u(2, 0x1000, 0), DEVICE_TYPE_3216, "node 2 (on B) from A's side")
                    # The other side sees the exchange too: its answer is taken before the next request.
                    vendor_id = client.upload_u(1, 0x1018, 1)
                    watcher.receive(lambda m: m.arbitration_id == 0x581, FRAME_TIMEOUT, "B's upload seen on A")
                    check_equal(watcher.upload_u(1, 0x1018, 1), vendor_id, "node 1's vendor ID from both sides")

                    # TMCL over CAN from B's side to the TMCM-1636 in A.
                    reply = TmclCan(client.bus).request(136, 1)
                    check_equal(reply[:3], bytes([1, 100, 136]), "TMCL reply of the TMCM-1636 across the link")

                    # Heartbeats of both sides, set from the other side; the watcher sees both.
                    watcher.download(2, 0x1017, 0, 50, 2)
                    client.download(1, 0x1017, 0, 50, 2)
                    beats = {}
                    deadline = time.monotonic() + FRAME_TIMEOUT
                    while not (beats.get(0x701, 0) >= 3 and beats.get(0x702, 0) >= 3):
                        check(time.monotonic() < deadline, f"heartbeats seen by A's watcher: {beats!r}")
                        msg = watcher.bus.recv(0.1)
                        if msg is not None and msg.arbitration_id in (0x701, 0x702):
                            check_equal(bytes(msg.data), b"\x7f", f"state in heartbeat {msg.arbitration_id:#x}")
                            beats[msg.arbitration_id] = beats.get(msg.arbitration_id, 0) + 1
                    client.receive(lambda m: m.arbitration_id == 0x701, FRAME_TIMEOUT, "node 1's heartbeat on B")
                    client.receive(lambda m: m.arbitration_id == 0x702, FRAME_TIMEOUT, "node 2's heartbeat on B")

                    # A TPDO of node 2 (in B), its statusword every 20 ms once operational, on A's side.
                    statusword = watcher.upload_u(2, 0x6041, 0)
                    watcher.configure_pdo(2, 0x1800, 0x182, 254, [0x60410010], event_ms=20)
                    watcher.send(0x000, [0x01, 2])  # NMT start node 2, from A's side
                    pdos = [watcher.receive(lambda m: m.arbitration_id == 0x182, FRAME_TIMEOUT, "node 2's TPDO")
                            for _ in range(3)]
                    check_equal({bytes(m.data) for m in pdos}, {struct.pack("<H", statusword)}, "TPDO data")
                    client.receive(lambda m: m.arbitration_id == 0x182, FRAME_TIMEOUT, "node 2's TPDO on B")
                    watcher.receive(lambda m: m.arbitration_id == 0x702 and bytes(m.data) == b"\x05",
                                    FRAME_TIMEOUT, "node 2 operational in its heartbeat")
                finally:
                    watcher.close()
                    client.close()
                check(a.alive() and b.alive(), "both serves still run")
                b.stop()
            a.stop()


def test_join_errors_at_start(motwin):
    with TempDir() as tmp:
        # Nobody listens.
        port = free_port()
        server = BusServer(motwin, os.path.join(tmp, "s"),
                           ["--node", "tmcm-3216:node-id=2", "--can", f"socketcand-client:127.0.0.1:{port}:can0"])
        try:
            check_equal(server.start_expect_failure(), 2, "exit status without a server")
            check_equal(server.stderr_lines(), [f"motwin: error: --can: cannot join the socketcand bus at "
                                                f"127.0.0.1:{port} can0: Connection refused"], "stderr")
        finally:
            server.cleanup()

        # A server that greets but refuses the channel (a socketcand daemon without that interface).
        listener = socket.socket()
        listener.bind(("127.0.0.1", 0))
        listener.listen(1)
        received = []

        def refuse_channel():
            connection, _ = listener.accept()
            with connection:
                connection.sendall(b"< hi >")
                received.append(connection.recv(100))
                connection.sendall(b"< error could not open bus >")
                connection.recv(100)  # until serve closes

        refuser = threading.Thread(target=refuse_channel, daemon=True)
        refuser.start()
        port = listener.getsockname()[1]
        server = BusServer(motwin, os.path.join(tmp, "s"),
                           ["--node", "tmcm-3216:node-id=2", "--can", f"socketcand-client:127.0.0.1:{port}:vcan7"])
        try:
            check_equal(server.start_expect_failure(), 2, "exit status when the channel is refused")
            check_equal(server.stderr_lines(), [f"motwin: error: --can: cannot join the socketcand bus at "
                                                f"127.0.0.1:{port} vcan7: the server answered < open vcan7 > "
                                                f"answered with < error could not open bus >"], "stderr")
        finally:
            server.cleanup()
        refuser.join(FRAME_TIMEOUT)
        listener.close()
        check_equal(received, [b"< open vcan7 >"], "what serve sent")

        # The channel is part of the endpoint.
        server = BusServer(motwin, os.path.join(tmp, "s"),
                           ["--node", "tmcm-3216", "--can", "socketcand-client:127.0.0.1:29536"])
        try:
            check_equal(server.start_expect_failure(), 2, "exit status without a channel")
            check("socketcand-client needs HOST:PORT:CHANNEL" in server.stderr_text(), server.stderr_text())
        finally:
            server.cleanup()


def test_server_goes_away_and_comes_back(motwin):
    with TempDir() as tmp:
        a = serve_a(motwin, tmp)
        a.start()
        port_a = a.port()
        try:
            with serve_b(motwin, tmp, port_a) as b:
                client = CanopenClient(b.port())
                try:
                    check_equal(client.upload_u(1, 0x1000, 0), DEVICE_TYPE_3216, "node 1 across")
                    a.stop()
                    wait_for_stderr(b, f"motwin: socketcand-client 127.0.0.1:{port_a} can0: connection lost (")
                    # B's own bus runs on: its node answers, the far node is gone.
                    check_equal(client.upload_u(2, 0x1000, 0), DEVICE_TYPE_3216, "node 2 while A is away")
                    client.send(0x601, UPLOAD_1000)
                    check_equal(collect(client.bus, 0.3, lambda m: m.arbitration_id == 0x581), [],
                                "node 1 while A is away")
                    # A is back on the same port: B joins again by itself.
                    a = serve_a(motwin, tmp, port_a)
                    a.start()
                    wait_for_stderr(b, f"motwin: socketcand-client 127.0.0.1:{port_a} can0: joined the bus again")
                    check_equal(client.upload_u(1, 0x1000, 0), DEVICE_TYPE_3216, "node 1 across again")
                    lost = [line for line in b.stderr_lines() if "socketcand-client" in line]
                    check_equal(len(lost), 2, f"one line for the loss, one for the return: {lost!r}")
                finally:
                    client.close()
                check(b.alive(), "B runs on")
                b.stop()
        finally:
            if a.alive():
                a.stop()
            a.cleanup()


if __name__ == "__main__":
    run_can_tests([test_two_serves_form_one_bus, test_join_errors_at_start, test_server_goes_away_and_comes_back])
