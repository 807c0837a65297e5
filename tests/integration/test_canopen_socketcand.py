#!/usr/bin/python3
"""CANopen (CiA-301) interoperability of the TMCM-3216 over the socketcand server, with Debian's
python3-can as the master's CAN interface and raw frames on the wire:

boot-up after NMT resets; SDO reads of 1000, 1018 and 1008 (segmented); SDO write and read-back
of 1017 and heartbeats at that period (simulated-time stamps); abort codes for absent objects,
sub-indices, read-only objects and wrong sizes; NMT start/stop/pre-operational with SDO refused
while stopped; store/restore (1010/1011) across a restart of the server; two clients see each
other's frames but not their own; garbage and malformed socketcand elements are tolerated;
malformed SDO frames (DLC 4, command specifier 7, a wrong toggle bit) get their aborts.
"""

import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import (  # noqa: E402
    NMT_PREOP, NMT_RESET_COMM, NMT_RESET_NODE, NMT_START, NMT_STOP, SAVE, STATE_BOOTUP, STATE_OPERATIONAL,
    STATE_PREOP, STATE_STOPPED, CanServer, RawSocketcand, check, check_equal, check_store_and_restore_across_restart,
    run_can_tests,
)
from motwin_harness import FRAME_TIMEOUT, TempDir  # noqa: E402

NODE = 5


def serve(motwin, tmp, **kwargs):
    return CanServer(motwin, os.path.join(tmp, "state"), node_id=kwargs.pop("node_id", NODE), **kwargs)


def test_bootup_after_nmt_reset(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        bus.nmt(NMT_RESET_NODE, NODE)
        msg = bus.wait_state(NODE, STATE_BOOTUP)
        check_equal(bytes(msg.data), b"\x00", "boot-up data")
        bus.nmt(NMT_RESET_COMM, 0)  # broadcast
        bus.wait_state(NODE, STATE_BOOTUP)
        bus.nmt(NMT_RESET_NODE, NODE + 1)  # another node: nothing
        frames = bus.collect(0.3, lambda m: m.arbitration_id == 0x700 + NODE)
        check_equal(frames, [], "frames after a reset for another node")
        server.stop()


def test_sdo_reads_of_identity_objects(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        check_equal(bus.upload_u(NODE, 0x1000, 0), 0xFFFF0192, "1000 device type")
        check_equal(bus.upload_u(NODE, 0x1018, 0), 4, "1018 sub 0")
        check_equal(bus.upload_u(NODE, 0x1018, 1), 0x286, "1018 vendor ID")
        check_equal(bus.upload_u(NODE, 0x1018, 2), 3216, "1018 product code")
        check_equal(bus.upload_u(NODE, 0x1018, 3), 0x00010004, "1018 revision")
        check_equal(bus.upload(NODE, 0x1008, 0), b"TMCM-3216", "1008 device name (segmented)")
        check_equal(bus.upload(NODE, 0x100A, 0), b"1.04", "100A software version")
        check_equal(bus.upload_u(NODE, 0x1014, 0), 0x80 + NODE, "1014 EMCY COB-ID")
        check_equal(bus.upload_u(NODE, 0x1800, 1), 0x180 + NODE, "1800 sub 1 TPDO 1 COB-ID")
        check_equal(bus.upload_u(NODE, 0x2708, 0), NODE, "2708 active node ID")
        server.stop()


def test_heartbeat_at_the_1017_period(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        bus.download(NODE, 0x1017, 0, 100, 2)
        check_equal(bus.upload_u(NODE, 0x1017, 0), 100, "1017 read back")
        beats = bus.collect_sim(NODE, 1.2, lambda m: m.arbitration_id == 0x700 + NODE)
        check(10 <= len(beats) <= 14, f"{len(beats)} heartbeats in 1.2 s (simulated) at 100 ms")
        for msg in beats:
            check_equal(bytes(msg.data), bytes([STATE_PREOP]), "heartbeat state")
        # Stamped with simulated time: exactly one period apart (1 ms tick resolution).
        gaps = [round((b.timestamp - a.timestamp) * 1000) for a, b in zip(beats, beats[1:])]
        check(all(gap == 100 for gap in gaps), f"heartbeat gaps in ms of sim time: {gaps}")
        bus.download(NODE, 0x1017, 0, 0, 2)
        bus.drain(0.05)
        check_equal(bus.collect(0.4, lambda m: m.arbitration_id == 0x700 + NODE), [], "heartbeats after 1017 = 0")
        server.stop()


def test_abort_codes(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        check_equal(bus.abort_code(bus.upload, NODE, 0x1234, 0), 0x06020000, "absent object")
        check_equal(bus.abort_code(bus.upload, NODE, 0x6043, 0), 0x06020000, "object not in the dictionary (vl mode)")
        check_equal(bus.abort_code(bus.upload, NODE, 0x1018, 9), 0x06090011, "absent sub-index")
        check_equal(bus.abort_code(bus.download, NODE, 0x1000, 0, 1, 4), 0x06010002, "write to 1000")
        check_equal(bus.abort_code(bus.download, NODE, 0x1017, 0, 1, 4), 0x06070012, "1017 with 4 bytes")
        check_equal(bus.abort_code(bus.download, NODE, 0x1017, 0, 1, 1), 0x06070013, "1017 with 1 byte")
        check_equal(bus.abort_code(bus.download, NODE, 0x1029, 1, 7, 1), 0x06090031, "1029 sub 1 too high")
        check_equal(bus.abort_code(bus.download, NODE, 0x1010, 1, 0x12345678, 4), 0x08000020, "bad signature")
        # Block upload request with block size 0: aborted with 05040002 (test_canopen_block.py does the rest).
        bus.send(0x600 + NODE, [0xA4, 0x08, 0x10, 0x00, 0x00, 0, 0, 0])
        msg = bus.receive(lambda m: m.arbitration_id == 0x580 + NODE, FRAME_TIMEOUT, "block upload answer")
        check_equal(bytes(msg.data), bytes([0x80, 0x08, 0x10, 0x00, 0x02, 0x00, 0x04, 0x05]), "block upload abort")
        # Still serving.
        check_equal(bus.upload_u(NODE, 0x1000, 0), 0xFFFF0192, "1000 after the aborts")
        server.stop()


def test_nmt_start_stop_preop(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        bus.download(NODE, 0x1017, 0, 50, 2)
        bus.wait_state(NODE, STATE_PREOP)
        bus.nmt(NMT_START, NODE)
        bus.wait_state(NODE, STATE_OPERATIONAL)
        bus.nmt(NMT_STOP, 0)
        bus.wait_state(NODE, STATE_STOPPED)
        bus.send(0x600 + NODE, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0])
        answers = bus.collect(0.3, lambda m: m.arbitration_id == 0x580 + NODE)
        check_equal(answers, [], "SDO answers while stopped")
        bus.wait_state(NODE, STATE_STOPPED)  # the heartbeat goes on
        bus.nmt(NMT_PREOP, NODE)
        bus.wait_state(NODE, STATE_PREOP)
        check_equal(bus.upload_u(NODE, 0x1000, 0), 0xFFFF0192, "SDO in pre-operational again")
        server.stop()


def test_store_and_restore_across_restart(motwin):
    def store_more(bus):
        bus.download(NODE, 0x1029, 1, 2, 1)

    def check_more_stored(bus):
        check_equal(bus.upload_u(NODE, 0x1029, 1), 2, "1029 sub 1 after restart")

    with TempDir() as tmp:
        check_store_and_restore_across_restart(lambda: serve(motwin, tmp), CanServer.bus, NODE, store_more,
                                               check_more_stored)


def test_node_id_through_2705_and_2706(motwin):
    with TempDir() as tmp:
        with serve(motwin, tmp, node_id=None) as server, server.bus() as bus:
            check_equal(bus.upload_u(1, 0x2708, 0), 1, "default node ID")
            bus.download(1, 0x2705, 0, 33, 1)
            bus.download(1, 0x2706, 1, SAVE, 4)
            bus.nmt(NMT_RESET_COMM, 1)
            bus.wait_state(33, STATE_BOOTUP)
            check_equal(bus.upload_u(33, 0x1014, 0), 0x80 + 33, "EMCY COB-ID follows the node ID")
            server.stop()
        with serve(motwin, tmp, node_id=None) as server, server.bus() as bus:
            check_equal(bus.upload_u(33, 0x2708, 0), 33, "stored node ID after restart")
            server.stop()


def test_clients_see_each_other_but_not_themselves(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as a, server.bus() as b:
        a.drain(0.1)
        b.drain(0.1)
        a.send(0x123, [1, 2, 3])
        msg = b.receive(lambda m: m.arbitration_id == 0x123, FRAME_TIMEOUT, "A's frame at B")
        check_equal(bytes(msg.data), b"\x01\x02\x03", "data")
        b.send(0x80, [])  # an empty frame (python-can sends "< send 80 0  >")
        msg = a.receive(lambda m: m.arbitration_id == 0x80, FRAME_TIMEOUT, "B's empty frame at A")
        check_equal(len(msg.data), 0, "empty frame length")
        check_equal(a.collect(0.3, lambda m: m.arbitration_id == 0x123), [], "A's own frame echoed to A")
        # Both see the node's answer to A's request.
        a.send(0x600 + NODE, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0])
        b.receive(lambda m: m.arbitration_id == 0x580 + NODE, FRAME_TIMEOUT, "SDO answer seen by B")
        server.stop()


def test_garbage_and_malformed_elements_are_tolerated(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server:
        raw = RawSocketcand(server.can_port)
        try:
            check_equal(raw.read_element(), "< hi >", "greeting")
            raw.send("junk < open can0 >")
            check_equal(raw.read_element(), "< ok >", "open")
            raw.send("< rawmode >")
            check_equal(raw.read_element(), "< ok >", "rawmode")
            raw.send("xx<<< send 601 8 40 >")  # a broken element, then a short send
            check(raw.read_element().startswith("< error"), "error for a bad send")
            raw.send("< send 605 2 40 >")  # length does not match
            check(raw.read_element().startswith("< error"), "error for a length mismatch")
            raw.send("< bogus command >")
            check(raw.read_element().startswith("< error"), "error for an unknown command")
            raw.send("<" + "x" * 1000 + ">")  # overlong: dropped silently
            raw.send("< echo >")
            check_equal(raw.read_element(), "< echo >", "echo")
            raw.send("< send 605 8 40 0 10 0 0 0 0 0 >")
            while True:
                element = raw.read_element()
                if element.startswith("< frame 585 "):
                    break
            parts = element.split()
            check_equal(parts[4], "430010009201FFFF", "SDO answer data")
            check(parts[3].count(".") == 1 and len(parts[3].split(".")[1]) == 6, f"timestamp {parts[3]}")
        finally:
            raw.close()
        with server.bus() as bus:
            check_equal(bus.upload_u(NODE, 0x1000, 0), 0xFFFF0192, "server still serves")
        server.stop()


def test_client_disconnect_mid_transfer(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server:
        with server.bus() as bus:
            bus.send(0x600 + NODE, [0x40, 0x08, 0x10, 0, 0, 0, 0, 0])  # segmented upload started
            bus.receive(lambda m: m.arbitration_id == 0x580 + NODE, FRAME_TIMEOUT, "initiate response")
        with server.bus() as bus:
            # The old transfer times out (05040000 after 1 s) or is replaced by this one.
            check_equal(bus.upload(NODE, 0x1008, 0), b"TMCM-3216", "a new transfer")
        check(server.alive(), "server alive")
        server.stop()


def test_malformed_sdo_frames_on_the_wire(motwin):
    """Robustness with raw frames: an SDO request of 4 bytes, command specifier 7 and an upload
    segment with the wrong toggle bit are aborted (05040001, 05040001, 05030000), and the server
    goes on serving."""
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        def exchange(data):
            bus.send(0x600 + NODE, data)
            msg = bus.receive(lambda m: m.arbitration_id == 0x580 + NODE, FRAME_TIMEOUT,
                              f"answer to {bytes(data).hex()}")
            return bytes(msg.data)

        check_equal(exchange([0x40, 0x00, 0x10, 0x00]), bytes([0x80, 0, 0, 0, 0x01, 0x00, 0x04, 0x05]),
                    "SDO request with DLC 4: 05040001")
        check_equal(exchange([0xE0, 0x00, 0x10, 0x00, 0, 0, 0, 0]), bytes([0x80, 0, 0, 0, 0x01, 0x00, 0x04, 0x05]),
                    "command specifier 7: 05040001")
        check_equal(exchange([0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]), bytes([0x41, 0x08, 0x10, 0x00, 9, 0, 0, 0]),
                    "initiate upload of 1008 (9 bytes, segmented)")
        check_equal(exchange([0x70, 0, 0, 0, 0, 0, 0, 0]), bytes([0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x03, 0x05]),
                    "first upload segment with toggle 1: 05030000")
        check_equal(exchange([0x60, 0, 0, 0, 0, 0, 0, 0]), bytes([0x80, 0, 0, 0, 0x01, 0x00, 0x04, 0x05]),
                    "a segment after the abort: no transfer (05040001)")
        check_equal(bus.upload(NODE, 0x1008, 0), b"TMCM-3216", "a good segmented upload afterwards")
        check_equal(bus.upload_u(NODE, 0x1000, 0), 0xFFFF0192, "and an expedited one")
        server.stop()


def test_heartbeat_consumer_emcy(motwin):
    """The master (node 0x10 here) sends heartbeats, then stops: EMCY 8130 with 1001 bit 4 (and
    bit 0), 1029 sub 1 = 0 stops the operational node; the next heartbeat gives EMCY 0000."""
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        bus.download(NODE, 0x1016, 1, (0x10 << 16) | 200, 4)  # producer 0x10, 200 ms
        bus.download(NODE, 0x1017, 0, 50, 2)
        bus.nmt(NMT_START, NODE)
        bus.wait_state(NODE, STATE_OPERATIONAL)
        for _ in range(3):
            bus.send(0x710, [0x05])
            bus.drain(0.05)
        emcy = bus.receive(lambda m: m.arbitration_id == 0x80 + NODE, FRAME_TIMEOUT, "EMCY after the heartbeats stop")
        check_equal(bytes(emcy.data), bytes([0x30, 0x81, 0x11, 0x00, 0xFF, 0x00, 0x00, 0x00]), "EMCY 8130")
        bus.wait_state(NODE, STATE_STOPPED)
        bus.send(0x710, [0x05])  # back: EMCY 0000 waits while stopped (no EMCY in stopped)...
        check_equal(bus.collect(0.2, lambda m: m.arbitration_id == 0x80 + NODE), [], "EMCY while stopped")
        bus.nmt(NMT_PREOP, NODE)  # ...and goes out in pre-operational
        emcy = bus.receive(lambda m: m.arbitration_id == 0x80 + NODE, FRAME_TIMEOUT, "EMCY 0000 in pre-operational")
        check_equal(bytes(emcy.data), bytes([0, 0, 0, 0, 0xFF, 0, 0, 0]), "EMCY 0000")
        # Another heartbeat first: the 200 ms since the last one may have run out again by now
        # (slow builds), which would set 1001 once more.
        bus.send(0x710, [0x05])
        check_equal(bus.upload_u(NODE, 0x1001, 0), 0x00, "1001 after the heartbeat came back")
        server.stop()


def test_bus_capture_pcap_and_candump(motwin):
    """--can-capture: pcap (link type 227, IDs big-endian) or candump -L log, simulated time."""
    import struct as st
    with TempDir() as tmp:
        for name in ("bus.pcap", "bus.log"):
            path = os.path.join(tmp, name)
            with serve(motwin, tmp, extra_args=("--can-capture", path)) as server, server.bus() as bus:
                bus.nmt(NMT_RESET_NODE, NODE)
                bus.wait_state(NODE, STATE_BOOTUP)
                check_equal(bus.upload_u(NODE, 0x1000, 0), 0xFFFF0192, "1000")
                server.stop()
            data = open(path, "rb").read()
            if name.endswith(".pcap"):
                magic, major, minor, _, _, snaplen, linktype = st.unpack_from("<IHHiIII", data, 0)
                check_equal((magic, major, minor, linktype), (0xA1B2C3D4, 2, 4, 227), "pcap header")
                frames = []
                offset = 24
                while offset < len(data):
                    sec, usec, incl, orig = st.unpack_from("<IIII", data, offset)
                    can_id, dlc = st.unpack_from(">IB", data, offset + 16)
                    frames.append((can_id, bytes(data[offset + 24:offset + 24 + dlc]), sec + usec / 1e6))
                    check_equal((incl, orig), (16, 16), "record length")
                    offset += 16 + incl
                check_equal(frames[0][:2], (0x000, bytes([NMT_RESET_NODE, NODE])), "first frame: the NMT reset")
                check_equal(frames[1][:2], (0x700 + NODE, b"\x00"), "boot-up")
                check_equal(frames[2][:2], (0x600 + NODE, bytes([0x40, 0, 0x10, 0, 0, 0, 0, 0])), "SDO request")
                check_equal(frames[3][:2], (0x580 + NODE, bytes([0x43, 0, 0x10, 0, 0x92, 1, 0xFF, 0xFF])),
                            "SDO response")
                check(frames[0][2] <= frames[3][2], "timestamps in order")
            else:
                lines = data.decode("ascii").splitlines()
                check(len(lines) >= 4, f"candump lines {lines!r}")
                check(lines[0].endswith(f" can0 000#81{NODE:02X}"), f"line 1 {lines[0]!r}")
                check(lines[1].endswith(f" can0 7{NODE:02X}#00"), f"line 2 {lines[1]!r}")
                check(lines[3].endswith(f" can0 58{NODE:X}#430010009201FFFF"), f"line 4 {lines[3]!r}")
                check(lines[0].startswith("(") and ") can0 " in lines[0], "candump -L form")


def test_serve_argument_errors(motwin):
    cases = [
        (["--can", "kvaser:0"], "--can: expected socketcand"),
        (["--can", "socketcand:127.0.0.1:0", "--tmcl-tcp", "127.0.0.1:0"], "has no TMCL interface"),
        (["--can", "socketcand:127.0.0.1:0", "--node-id", "128"], "--node-id"),
    ]
    with TempDir() as tmp:
        for extra, expected in cases:
            server = CanServer(motwin, "none")
            server.args = [motwin, "serve", "--module", "tmcm-3216", "--state-dir", "none"] + extra
            try:
                check_equal(server.start_expect_failure(), 2, f"exit status for {extra}")
                lines = server.stderr_lines()
                check(len(lines) == 1 and lines[0].startswith("motwin: error: ") and expected in lines[0],
                      f"stderr for {extra}: {lines!r}")
            finally:
                server.cleanup()
        del tmp


def main():
    run_can_tests([
        test_bootup_after_nmt_reset,
        test_sdo_reads_of_identity_objects,
        test_heartbeat_at_the_1017_period,
        test_abort_codes,
        test_nmt_start_stop_preop,
        test_store_and_restore_across_restart,
        test_node_id_through_2705_and_2706,
        test_clients_see_each_other_but_not_themselves,
        test_garbage_and_malformed_elements_are_tolerated,
        test_client_disconnect_mid_transfer,
        test_malformed_sdo_frames_on_the_wire,
        test_heartbeat_consumer_emcy,
        test_bus_capture_pcap_and_candump,
        test_serve_argument_errors,
    ])


if __name__ == "__main__":
    main()
