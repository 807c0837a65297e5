#!/usr/bin/python3
"""The virtual CAN bus as a whole, with Debian's python3-can and tshark:
- several modules on one bus in one process (`--node`): two TMCM-3216 (node IDs 1 and 2) and a
  TMCM-1636 on one socketcand server, each answering only its own identifiers;
- `motwin candump` lines against the frames a python-can client saw;
- a `--can-capture` pcap of NMT, SDO, heartbeat and EMCY decoded by tshark as CANopen without
  malformed packets or expert errors, with the decoded fields checked;
- bus load: `--can-stats` lines, frame spacing at the bit rate, a flood that the bus keeps serving;
- robustness: malformed socketcand and SLCAN input, a client leaving mid-transfer;
- SocketCAN: a clear error where the kernel has no AF_CAN (the live part then skips).
"""

import os
import re
import shutil
import socket
import struct
import subprocess
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from can_bus_harness import (  # noqa: E402
    BusServer, TmclCan, check, check_equal, collect, collect_through, open_bus, receive,
)
from canopen_harness import CanopenClient, RawSocketcand  # noqa: E402
from motwin_harness import FRAME_TIMEOUT, TempDir, bytes_received_at, run_tests  # noqa: E402


def sdo_upload_u32(bus, node, index, sub):
    import can
    bus.send(can.Message(arbitration_id=0x600 + node, data=[0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0],
                         is_extended_id=False))
    msg = receive(bus, lambda m: m.arbitration_id == 0x580 + node, FRAME_TIMEOUT, f"SDO answer of node {node}")
    return struct.unpack_from("<I", bytes(msg.data), 4)[0]


def test_several_modules_on_one_bus(motwin):
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        args = ["--node", "tmcm-3216:node-id=1", "--node", "tmcm-3216:node-id=2,name=right",
                "--node", "tmcm-1636", "--can", "socketcand:127.0.0.1:0"]
        with BusServer(motwin, state, args) as server:
            check_equal([(b[0], b[1]) for b in server.banners],
                        [("tmcm-3216-1", "tmcm-3216"), ("right", "tmcm-3216"), ("tmcm-1636-3", "tmcm-1636")],
                        "one banner line per node")
            check_equal(server.banners[1][3], os.path.join(state, "right", "tmcm-3216.eeprom"), "per-node image")
            bus = open_bus(server.port())
            try:
                import can
                time.sleep(0.1)
                collect(bus, 0.05)
                # NMT reset of node 2 only: one boot-up, from 0x702.
                bus.send(can.Message(arbitration_id=0, data=[0x81, 2], is_extended_id=False))
                boots = collect_through(bus, lambda m: 0x700 <= m.arbitration_id < 0x780,
                                        lambda m: m.arbitration_id == 0x702)
                check_equal([(m.arbitration_id, bytes(m.data)) for m in boots], [(0x702, b"\x00")], "boot-ups")
                for node in (1, 2):
                    bus.send(can.Message(arbitration_id=0x600 + node, data=[0x40, 0x00, 0x10, 0, 0, 0, 0, 0],
                                         is_extended_id=False))
                    answers = collect_through(bus, lambda m: 0x580 <= m.arbitration_id < 0x600 or m.arbitration_id == 2,
                                              lambda m: m.arbitration_id == 0x580 + node)
                    check_equal([m.arbitration_id for m in answers], [0x580 + node], f"answers to node {node}'s SDO")
                    check_equal(struct.unpack_from("<I", bytes(answers[0].data), 4)[0], 0xFFFF0192, "1000")
                # 1018 sub 4 and the TMCL module beside them.
                tmcl = TmclCan(bus)
                tmcl.send_raw([136, 1, 0, 0, 0, 0, 0])
                answers = collect_through(bus, lambda m: m.arbitration_id != 0x701 and m.arbitration_id != 0x702,
                                          lambda m: m.arbitration_id == 2)
                check_equal([(m.arbitration_id, bytes(m.data)) for m in answers],
                            [(2, bytes([1, 100, 136, 0x06, 0x64, 0x01, 0x09]))], "only the TMCM-1636 answers TMCL")
                # Node 3 does not exist: silence.
                bus.send(can.Message(arbitration_id=0x603, data=[0x40, 0x00, 0x10, 0, 0, 0, 0, 0], is_extended_id=False))
                check_equal(collect(bus, 0.3, lambda m: m.arbitration_id == 0x583), [], "answer from an absent node")
            finally:
                bus.shutdown()
            server.stop()


def test_node_option_errors(motwin):
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        cases = [
            (["--node", "tmcm-3216:node-id=1", "--tmcl-tcp", "127.0.0.1:0"], "cannot be combined"),
            (["--node", "tmcm-3216:name=a", "--node", "tmcm-3216:name=a"], "two nodes named \"a\""),
            (["--node", "tmcm-9999"], "unknown module"),
            (["--node", "tmcm-3216:node-id=300"], "node-id must be 1..127"),
            (["--module", "tmcm-3216", "--can", "socketcand:127.0.0.1:0", "--can-bitrate", "2M"], "--can-bitrate"),
        ]
        for args, message in cases:
            server = BusServer(motwin, state, args)
            status = server.start_expect_failure()
            check_equal(status, 2, f"exit status of {args}")
            check(message in server.stderr_text(), f"{args}: expected {message!r} in {server.stderr_text()!r}")


def test_candump_prints_the_bus(motwin):
    with TempDir() as tmp, BusServer(motwin, os.path.join(tmp, "state"),
                                     ["--module", "tmcm-3216", "--node-id", "4", "--can", "socketcand:127.0.0.1:0"]) as server:
        dump = subprocess.Popen([motwin, "candump", "--can", f"socketcand:127.0.0.1:{server.port()}", "--count", "4",
                                 "--timeout", "5"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        try:
            # candump connected and in raw mode: the server has read its two commands (the only
            # client yet). A loaded machine may take seconds to start it.
            handshake = len("< open can0 >") + len("< rawmode >")
            deadline = time.monotonic() + 60.0
            while bytes_received_at(server.port()) != [handshake]:
                check(dump.poll() is None and time.monotonic() < deadline,
                      f"candump not in raw mode: the server read {bytes_received_at(server.port())} bytes")
                time.sleep(0.01)
            client = CanopenClient(server.port())
            try:
                client.send(0x123, [0xDE, 0xAD])
                client.send(0x7FF, [])
                check_equal(client.upload_u(4, 0x1000, 0), 0xFFFF0192, "SDO while candump listens")
            finally:
                client.close()
            out, err = dump.communicate(timeout=10)
        finally:
            if dump.poll() is None:
                dump.kill()
        check_equal(dump.returncode, 0, f"candump exit status (stderr {err!r})")
        lines = out.decode().splitlines()
        pattern = re.compile(r"\((\d+)\.(\d{6})\) can0 ([0-9A-F]{3})#([0-9A-F]*)")
        parsed = []
        for line in lines:
            m = pattern.fullmatch(line)
            check(m is not None, f"candump line {line!r}")
            parsed.append((m.group(3), m.group(4)))
        check_equal(parsed, [("123", "DEAD"), ("7FF", ""), ("604", "4000100000000000"), ("584", "430010009201FFFF")],
                    "candump frames")
        stamps = [float(line[1:line.index(")")]) for line in lines]
        check(stamps == sorted(stamps), f"timestamps in order: {stamps}")
        # Without frames, --timeout ends it with status 1 when --count was not reached.
        quiet = subprocess.run([motwin, "candump", "--can", f"socketcand:127.0.0.1:{server.port()}", "--count", "1",
                                "--timeout", "0.3"], capture_output=True, timeout=10)
        check_equal((quiet.returncode, quiet.stdout), (1, b""), "candump on a quiet bus")
        server.stop()
    refused = subprocess.run([motwin, "candump", "--can", "socketcand:127.0.0.1:1", "--count", "1"],
                             capture_output=True, timeout=10)
    check_equal(refused.returncode, 2, "candump without a server")


def tshark_fields(path, *fields):
    out = subprocess.run(["tshark", "-r", path, "-d", "can.subdissector,canopen", "-T", "fields", "-E", "separator=;",
                          *sum((["-e", f] for f in fields), [])], capture_output=True, timeout=60, check=True)
    return [line.split(";") for line in out.stdout.decode().splitlines()]


def test_tshark_decodes_a_capture_as_canopen(motwin):
    if shutil.which("tshark") is None:
        print("SKIP: tshark is not installed (scripts/install-deps.sh installs it)")
        return
    with TempDir() as tmp:
        capture = os.path.join(tmp, "bus.pcap")
        with BusServer(motwin, os.path.join(tmp, "state"),
                       ["--module", "tmcm-3216", "--node-id", "5", "--can", "socketcand:127.0.0.1:0",
                        "--can-capture", capture]) as server:
            client = CanopenClient(server.port())
            try:
                client.nmt(0x81, 5)
                client.wait_state(5, 0x00)
                check_equal(client.upload(5, 0x1008, 0), b"TMCM-3216", "segmented upload")
                client.download(5, 0x1017, 0, 100, 2)
                # Heartbeat consumer on node 0x7F (100 ms): one heartbeat, then silence -> EMCY 8130.
                client.download(5, 0x1016, 1, (0x7F << 16) | 100, 4)
                client.send(0x77F, [0x05])
                emcy = client.receive(lambda m: m.arbitration_id == 0x85, FRAME_TIMEOUT, "EMCY of node 5")
                check_equal(struct.unpack_from("<H", bytes(emcy.data), 0)[0], 0x8130, "EMCY error code")
                client.abort_code(client.upload, 5, 0x1234, 0)
                client.nmt(0x01, 5)
                client.wait_state(5, 0x05)
            finally:
                client.close()
            server.stop()
        malformed = subprocess.run(["tshark", "-r", capture, "-d", "can.subdissector,canopen", "-Y",
                                    "_ws.malformed || _ws.expert.severity >= 6291456"],
                                   capture_output=True, timeout=60)
        check_equal(malformed.returncode, 0, f"tshark status (stderr {malformed.stderr!r})")
        check_equal(malformed.stdout.decode().strip(), "", "malformed packets or expert errors")
        rows = tshark_fields(capture, "can.id", "_ws.col.Protocol", "canopen.function_code", "canopen.nmt_ctrl.cd",
                             "canopen.nmt_guard.state", "canopen.sdo.ccs", "canopen.sdo.scs", "canopen.sdo.main_idx",
                             "canopen.sdo.abort_code", "canopen.em.err_code")
        check(len(rows) >= 12, f"{len(rows)} frames in the capture")
        check(all(row[1] == "CANopen" for row in rows), f"every frame decoded as CANopen: {[r[1] for r in rows]}")
        check_equal(rows[0][0:4], ["0", "CANopen", "0x00000000", "0x81"], "first frame: NMT reset node")
        check_equal((rows[1][0], rows[1][4]), ("1797", "0x00"), "boot-up of node 5 (0x705)")
        check_equal((rows[2][5], rows[2][7]), ("2", "0x1008"), "initiate upload request (ccs 2) of 1008")
        check_equal((rows[3][6], rows[3][7]), ("2", "0x1008"), "initiate upload response (scs 2)")
        check(any(r[5] == "1" and r[7] == "0x1017" for r in rows), "initiate download request (ccs 1) of 1017")
        check(any(r[6] == "4" and r[8] == "0x06020000" for r in rows), "abort 06020000 decoded")
        check(any(r[9] == "0x8130" for r in rows), "EMCY 8130 decoded")
        check(any(r[3] == "0x01" for r in rows), "NMT start decoded")
        check(any(r[0] == "1797" and r[4] == "0x05" for r in rows), "heartbeat 'operational' decoded")


def test_bus_load_and_a_flood(motwin):
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        # The node must run at the bus's 125 kbit/s (a node at another rate is cut off,
        # test_can_bitrate.py): 2704 = 125 stored first, on a 1 Mbit/s bus.
        with BusServer(motwin, state, ["--module", "tmcm-3216", "--node-id", "3",
                                       "--can", "socketcand:127.0.0.1:0"]) as server:
            client = CanopenClient(server.port())
            try:
                client.download(3, 0x2704, 0, 125, 2)
                client.download(3, 0x2706, 1, 0x65766173, 4)  # "save"
            finally:
                client.close()
            server.stop()
        with BusServer(motwin, state, ["--module", "tmcm-3216", "--node-id", "3", "--can", "socketcand:127.0.0.1:0",
                                       "--can-bitrate", "125k", "--can-stats", "0.3"]) as server:
            flood = RawSocketcand(server.port())
            try:
                for expected in ("< hi >",):
                    check_equal(flood.read_element(), expected, "greeting")
                flood.send("< open can0 >< rawmode >")
                # 3000 frames at once: far beyond what 125 kbit/s carries in the moment they arrive.
                flood.send("".join(f"< send 7{i % 16:X}0 8 1 2 3 4 5 6 7 8 >" for i in range(3000)))
                client = CanopenClient(server.port())
                try:
                    check_equal(client.upload_u(3, 0x1000, 0), 0xFFFF0192, "SDO during the flood")
                finally:
                    client.close()
            finally:
                flood.close()
            # The counts are totals: the first line that counts the whole flood (a loaded machine
            # may take several intervals to carry it).
            stats_line = re.compile(r"can-stats frames (\d+) \(\+(\d+)\) bits (\d+) load ([\d.]+)% queue-delay mean "
                                    r"([\d.]+) ms max ([\d.]+) ms bitrate (\d+)")
            deadline = time.monotonic() + 60
            while True:
                stats = [l for l in server.stdout_lines if l.startswith("can-stats")]
                for line in stats:
                    check(stats_line.match(line) is not None, f"can-stats format: {line!r}")
                m = next((m for m in map(stats_line.match, stats) if int(m.group(1)) >= 3000), None)
                if m is not None:
                    break
                check(time.monotonic() < deadline, f"frames counted: {stats!r}")
                time.sleep(0.05)
            check_equal(int(m.group(7)), 125000, "bit rate in can-stats")
            # 3000 frames of ~130 bits at 125 kbit/s are ~3 s of bus time: a long queue.
            check(float(m.group(6)) > 1000.0, f"max queueing delay shows the overload: {stats!r}")
            server.stop()


def test_malformed_input_and_clients_leaving_mid_transfer(motwin):
    with TempDir() as tmp, BusServer(motwin, os.path.join(tmp, "state"),
                                     ["--module", "tmcm-3216", "--node-id", "6", "--can", "socketcand:127.0.0.1:0",
                                      "--can", "slcan-tcp:127.0.0.1:0"]) as server:
        raw = RawSocketcand(server.port())
        try:
            check_equal(raw.read_element(), "< hi >", "greeting")
            raw.send("garbage< open can0 >")
            check_equal(raw.read_element(), "< ok >", "open after garbage")
            raw.send("< rawmode >")
            check_equal(raw.read_element(), "< ok >", "rawmode")
            raw.send("< send 606 9 1 2 3 4 5 6 7 8 9 >")
            check(raw.read_element().startswith("< error"), "DLC 9 refused")
            raw.send("< send XYZ 1 00 >")
            check(raw.read_element().startswith("< error"), "bad ID refused")
            raw.send(b"<\xff\xfe\x00 >< frobnicate >")
            check(raw.read_element().startswith("< error"), "binary element answered with an error")
            check(raw.read_element().startswith("< error"), "unknown command answered with an error")
            # A segmented upload started and abandoned by a client that disconnects.
            raw.send("< send 606 8 40 8 10 0 0 0 0 0 >")
            answer = raw.read_element()
            check(answer.startswith("< frame 586 ") and answer.endswith(" 4108100009000000 >"),
                  f"initiate upload response of 1008 (9 bytes): {answer!r}")
        finally:
            raw.close()
        slcan = socket.create_connection(("127.0.0.1", server.port("can-slcan-tcp")), timeout=5)
        try:
            slcan.sendall(b"O\r" + b"x" * 200 + b"\rt6068\r\x00\x00\r")
            data = b""
            while b"\a" not in data:  # the answers may come in several pieces
                chunk = slcan.recv(4096)
                check(chunk, f"BEL for SLCAN garbage: {data!r}, then the connection closed")
                data += chunk
            check(b"\a" in data, f"BEL for SLCAN garbage: {data!r}")
        finally:
            slcan.close()
        client = CanopenClient(server.port())
        try:
            # The stale transfer is replaced by a new initiate; the node keeps serving.
            check_equal(client.upload(6, 0x1008, 0), b"TMCM-3216", "segmented upload after the abandoned one")
            check_equal(client.upload_u(6, 0x1000, 0), 0xFFFF0192, "expedited upload")
        finally:
            client.close()
        server.stop()


def af_can_available():
    try:
        s = socket.socket(socket.AF_CAN, socket.SOCK_RAW, socket.CAN_RAW)
    except (OSError, AttributeError):
        return False
    s.close()
    return True


def test_socketcan_endpoint(motwin):
    with TempDir() as tmp:
        server = BusServer(motwin, os.path.join(tmp, "state"), ["--module", "tmcm-3216", "--can", "socketcan:motwin0"])
        status = server.start_expect_failure()
        check_equal(status, 2, "exit status with a SocketCAN interface that does not exist")
        expected = "no such CAN interface" if af_can_available() else "no SocketCAN"
        check(expected in server.stderr_text(), f"expected {expected!r} in {server.stderr_text()!r}")
        if not af_can_available():
            print("SKIP: the kernel has no AF_CAN here; the live SocketCAN part is not run")
            return
        if not os.path.exists("/sys/class/net/vcan0"):
            print("SKIP: no vcan0 interface (ip link add dev vcan0 type vcan)")
            return
        with BusServer(motwin, os.path.join(tmp, "state"),
                       ["--module", "tmcm-3216", "--node-id", "8", "--can", "socketcan:vcan0"]) as live:
            import can
            bus = can.Bus(interface="socketcan", channel="vcan0")
            try:
                check_equal(sdo_upload_u32(bus, 8, 0x1000, 0), 0xFFFF0192, "SDO over vcan0")
            finally:
                bus.shutdown()
            live.stop()


if __name__ == "__main__":
    run_tests([test_several_modules_on_one_bus, test_node_option_errors, test_candump_prints_the_bus,
               test_tshark_decodes_a_capture_as_canopen, test_bus_load_and_a_flood,
               test_malformed_input_and_clients_leaving_mid_transfer, test_socketcan_endpoint])
