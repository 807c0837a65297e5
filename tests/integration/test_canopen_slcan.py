#!/usr/bin/python3
"""SLCAN over TCP (`--can slcan-tcp:127.0.0.1:0`) with Debian's python3-can (`interface='slcan'`,
channel `socket://127.0.0.1:PORT`, the pyserial URL): NMT reset and boot-up, SDO expedited and
segmented, heartbeat, and one bus shared with a socketcand client (each sees the other's frames,
neither sees its own). The rest of the checklist of docs/canopen.md
("Device contract masters rely on") over SLCAN too: PDO reconfiguration in python-canopen's order,
SYNC-driven and event-timer TPDOs, RPDO length EMCYs, NMT transitions, store/restore across a
restart, LSS configure, store and fastscan. Plus the adapter protocol by hand: version, status,
errors for frames while closed, bit rate change refused while open, garbage lines answered with BEL.
"""

import os
import socket
import struct
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import (  # noqa: E402
    NMT_PREOP, NMT_RESET_COMM, NMT_RESET_NODE, NMT_START, NMT_STOP, SAVE, STATE_BOOTUP, STATE_OPERATIONAL,
    STATE_PREOP, STATE_STOPPED, CanServer, TestFailure, check, check_equal, check_store_and_restore_across_restart,
    run_can_tests,
)
from motwin_harness import FRAME_TIMEOUT, TempDir  # noqa: E402

NODE = 7


def serve(motwin, tmp):
    return CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE,
                     can=("slcan-tcp:127.0.0.1:0", "socketcand:127.0.0.1:0"))


def test_slcan_sdo_and_nmt(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.slcan_bus() as bus, server.bus() as clock:
        bus.nmt(NMT_RESET_NODE, NODE)
        bus.wait_state(NODE, STATE_BOOTUP)
        check_equal(bus.upload_u(NODE, 0x1000, 0), 0xFFFF0192, "1000 over SLCAN")
        check_equal(bus.upload(NODE, 0x1008, 0), b"TMCM-3216", "1008 over SLCAN (segmented)")
        bus.download(NODE, 0x1017, 0, 50, 2)
        # 0.5 s of simulated time: the socketcand client's stamps tell it (SLCAN's are wall time).
        beats = bus.collect_sim(NODE, 0.5, lambda m: m.arbitration_id == 0x700 + NODE, clock=clock)
        check(8 <= len(beats) <= 12, f"{len(beats)} heartbeats in 0.5 s (simulated) at 50 ms")
        check(all(bytes(m.data) == bytes([STATE_PREOP]) for m in beats), "heartbeat state")
        server.stop()


def test_slcan_and_socketcand_share_the_bus(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.slcan_bus() as slcan, server.bus() as socketcand:
        socketcand.drain(0.1)
        slcan.send(0x321, [9, 8, 7])
        msg = socketcand.receive(lambda m: m.arbitration_id == 0x321, FRAME_TIMEOUT,
                                 "SLCAN frame at the socketcand client")
        check_equal(bytes(msg.data), b"\x09\x08\x07", "data")
        socketcand.send(0x322, [1])
        msg = slcan.receive(lambda m: m.arbitration_id == 0x322, FRAME_TIMEOUT, "socketcand frame at the SLCAN client")
        check_equal(bytes(msg.data), b"\x01", "data")
        check_equal(slcan.collect(0.3, lambda m: m.arbitration_id == 0x321), [], "own frame echoed over SLCAN")
        server.stop()


DUMMY_U8, DUMMY_U16 = 0x00050008, 0x00060010


def sync_and_collect(bus, count, cob_id, stopped=False):
    """Sends `count` SYNCs; returns the SYNC numbers (1-based) after which the TPDO came: before
    the node's answer to the marker that follows each SYNC. A stopped node answers no marker:
    then whatever comes within 50 ms counts (no TPDO is expected)."""
    answered = []
    for n in range(1, count + 1):
        bus.send(0x080, [])
        is_tpdo = lambda m: m.arbitration_id == cob_id  # noqa: E731
        if bus.collect(0.05, is_tpdo) if stopped else bus.frames_until_marker(NODE, is_tpdo):
            answered.append(n)
    return answered


def test_slcan_pdo_sync_and_emcy(motwin):
    """PDO reconfiguration in python-canopen's order, a SYNC-driven TPDO, an event-timer TPDO and
    the RPDO length EMCYs, all through the SLCAN adapter (python-can stamps SLCAN frames with wall
    time, so counts are checked, not gaps)."""
    with TempDir() as tmp, serve(motwin, tmp) as server, server.slcan_bus() as bus, server.bus() as clock:
        tpdo1, tpdo2, rpdo1, emcy = 0x180 + NODE, 0x280 + NODE, 0x200 + NODE, 0x80 + NODE
        bus.configure_pdo(NODE, 0x1800, tpdo1, 3, [DUMMY_U16])
        bus.configure_pdo(NODE, 0x1801, tpdo2, 0xFF, [DUMMY_U8], event_ms=100)
        bus.configure_pdo(NODE, 0x1400, rpdo1, 0xFF, [DUMMY_U16, DUMMY_U8])
        check_equal([bus.upload_u(NODE, 0x1A00, sub) for sub in (0, 1)], [1, DUMMY_U16], "1A00 read back")
        check_equal(bus.upload_u(NODE, 0x1800, 2), 3, "1800 sub 2 read back")
        check_equal(bus.upload_u(NODE, 0x1801, 5), 100, "1801 sub 5 read back")
        check_equal(sync_and_collect(bus, 3, tpdo1), [], "TPDOs at SYNCs in pre-operational")
        bus.nmt(NMT_START, NODE)
        frames = bus.collect_sim(NODE, 0.55, lambda m: m.arbitration_id == tpdo2, clock=clock)
        check(4 <= len(frames) <= 7, f"{len(frames)} event-timer TPDOs in 0.55 s (simulated) at 100 ms")
        check(all(bytes(m.data) == b"\0" for m in frames), "TPDO 2 data (one dummy byte)")
        check_equal(sync_and_collect(bus, 9, tpdo1), [3, 6, 9], "type 3: every third SYNC")
        bus.send(rpdo1, [1, 2])
        msg = bus.receive(lambda m: m.arbitration_id == emcy, FRAME_TIMEOUT, "EMCY 8210")
        check_equal(bytes(msg.data), bytes([0x10, 0x82, 0x11, 0x00, 0xFF, 0, 0, 0]), "EMCY 8210 (RPDO too short)")
        bus.send(rpdo1, [1, 2, 3])
        msg = bus.receive(lambda m: m.arbitration_id == emcy, FRAME_TIMEOUT, "EMCY 0000")
        check_equal(bytes(msg.data), bytes([0, 0, 0, 0, 0xFF, 0, 0, 0]), "EMCY 0000 (error reset)")
        bus.nmt(NMT_STOP, NODE)
        bus.drain(0.05)
        check_equal(sync_and_collect(bus, 3, tpdo1, stopped=True), [], "TPDOs at SYNCs while stopped")
        server.stop()


def test_slcan_nmt_transitions(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.slcan_bus() as bus, server.bus() as clock:
        bus.download(NODE, 0x1017, 0, 1000, 2)  # state changes show as extra heartbeats at once
        bus.wait_state(NODE, STATE_PREOP)
        # Each NMT command over SLCAN, and the heartbeat it brings within 0.5 s of simulated time
        # (the socketcand client sees both with their bus times), which the SLCAN client gets too.
        bus.nmt(NMT_START, NODE)
        clock.state_after_nmt(NODE, NMT_START, STATE_OPERATIONAL, within=0.5)
        bus.wait_state(NODE, STATE_OPERATIONAL)
        bus.nmt(NMT_STOP, 0)
        clock.state_after_nmt(NODE, NMT_STOP, STATE_STOPPED, within=0.5)
        bus.wait_state(NODE, STATE_STOPPED)
        bus.send(0x600 + NODE, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0])
        check_equal(bus.collect(0.3, lambda m: m.arbitration_id == 0x580 + NODE), [], "SDO answers while stopped")
        bus.nmt(NMT_PREOP, NODE)
        clock.state_after_nmt(NODE, NMT_PREOP, STATE_PREOP, within=0.5)
        bus.wait_state(NODE, STATE_PREOP)
        check_equal(bus.upload_u(NODE, 0x1000, 0), 0xFFFF0192, "SDO in pre-operational again")
        bus.nmt(NMT_RESET_COMM, NODE)
        bus.wait_state(NODE, STATE_BOOTUP)
        check_equal(bus.upload_u(NODE, 0x1017, 0), 0, "1017 after reset communication")
        server.stop()


def test_slcan_store_and_restore_across_restart(motwin):
    def store_more(bus):
        bus.configure_pdo(NODE, 0x1802, 0x380 + NODE, 7, [DUMMY_U8])

    def check_more_stored(bus):
        check_equal(bus.upload_u(NODE, 0x1802, 2), 7, "1802 sub 2 after restart")
        check_equal([bus.upload_u(NODE, 0x1A02, sub) for sub in (0, 1)], [1, DUMMY_U8], "1A02 after restart")

    def check_more_restored(bus):
        check_equal(bus.upload_u(NODE, 0x1802, 2), 1, "1802 sub 2 back to table 45's default")

    with TempDir() as tmp:
        check_store_and_restore_across_restart(lambda: serve(motwin, tmp), CanServer.slcan_bus, NODE, store_more,
                                               check_more_stored, check_more_restored)


def lss_answer(bus, data, timeout=0.06):
    """One LSS frame; the slave's answer (0x7E4) or None when nobody answers within `timeout`."""
    bus.send(0x7E5, list(data) + [0] * (8 - len(data)))
    frames = []
    deadline = time.monotonic() + timeout
    while not frames and time.monotonic() < deadline:
        msg = bus.bus.recv(deadline - time.monotonic())
        if msg is not None and msg.arbitration_id == 0x7E4:
            frames.append(bytes(msg.data))
    return frames[0] if frames else None


def test_slcan_lss_configure_and_fastscan(motwin):
    """Switch state selective, inquire, configure node ID and store on a configured node; then the
    node made unconfigured (2705 = 255), found by fastscan, configured and booted: all over SLCAN
    (a socketcand client only listens, to tell fastscan's unanswered questions for sure)."""
    endpoints = ("slcan-tcp:127.0.0.1:0", "socketcand:127.0.0.1:0")
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        with CanServer(motwin, state, can=endpoints) as server, server.slcan_bus() as bus, server.bus() as listener:
            ident = [bus.upload_u(1, 0x1018, sub) for sub in (1, 2, 3, 4)]
            check_equal(ident, [0x286, 3216, 0x00010004, 1], "identity of node 1")
            for command, value in zip((0x40, 0x41, 0x42), ident[:3]):
                check_equal(lss_answer(bus, [command] + list(struct.pack("<I", value)), timeout=0.1), None,
                            f"answer to {command:#04x}")
            check_equal(lss_answer(bus, [0x43] + list(struct.pack("<I", ident[3])), timeout=10.0),
                        bytes([0x44]) + bytes(7), "switch state selective answer")
            check_equal(lss_answer(bus, [0x5E], timeout=10.0)[:2], bytes([0x5E, 1]), "inquire node ID")
            check_equal(lss_answer(bus, [0x11, 23], timeout=10.0)[:2], bytes([0x11, 0]), "configure node ID 23")
            check_equal(lss_answer(bus, [0x17], timeout=10.0)[:2], bytes([0x17, 0]), "store configuration")
            bus.send(0x7E5, [0x04, 0, 0, 0, 0, 0, 0, 0])  # waiting
            bus.nmt(NMT_RESET_COMM, 1)
            bus.wait_state(23, STATE_BOOTUP)
            check_equal(bus.upload_u(23, 0x2705, 0), 23, "2705 stored by LSS")
            check_equal(bus.lss_fastscan(listener), None, "fastscan of a configured node")
            bus.download(23, 0x2705, 0, 255, 1)
            bus.download(23, 0x2706, 1, SAVE, 4)
            server.stop()
        with CanServer(motwin, state, can=endpoints) as server, server.slcan_bus() as bus, server.bus() as listener:
            bus.send(0x623, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0])
            check_equal(bus.collect(0.3, lambda m: m.arbitration_id != 0x7E4), [], "frames of an unconfigured node")
            check_equal(bus.lss_fastscan(listener), ident, "identity found by fastscan")
            check_equal(lss_answer(bus, [0x11, 20], timeout=10.0)[:2], bytes([0x11, 0]), "configure node ID 20")
            bus.send(0x7E5, [0x04, 0, 0, 0, 0, 0, 0, 0])  # waiting: the unconfigured node boots at once
            bus.wait_state(20, STATE_BOOTUP)
            check_equal(bus.upload_u(20, 0x1000, 0), 0xFFFF0192, "SDO to the new node ID")
            server.stop()


class RawSlcan:
    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        self.buffer = b""

    def command(self, text, timeout=10.0):
        """Sends one line; returns the answer up to and including the first CR or BEL."""
        self.sock.sendall(text.encode("ascii") + b"\r")
        return self.read_answer(timeout, text)

    def read_answer(self, timeout=10.0, text="(nothing sent)"):
        deadline = time.monotonic() + timeout
        while True:
            for i, byte in enumerate(self.buffer):
                if byte in (0x0D, 0x07):
                    answer, self.buffer = self.buffer[:i + 1], self.buffer[i + 1:]
                    return answer
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TestFailure(f"no SLCAN answer to {text!r} (have {self.buffer!r})")
            self.sock.settimeout(remaining)
            chunk = self.sock.recv(4096)
            if not chunk:
                raise TestFailure("SLCAN server closed the connection")
            self.buffer += chunk

    def close(self):
        self.sock.close()


def test_slcan_adapter_commands(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server:
        raw = RawSlcan(server.slcan_port)
        try:
            check_equal(raw.command("V"), b"V1013\r", "version")
            check_equal(raw.command("F"), b"F00\r", "status flags")
            check_equal(raw.command("t60584000100000000000"), b"\a", "frame while closed")
            check_equal(raw.command("S6"), b"\r", "bit rate while closed")
            check_equal(raw.command("O"), b"\r", "open")
            check_equal(raw.command("S8"), b"\a", "bit rate while open")
            check_equal(raw.command("xyz"), b"\a", "garbage")
            check_equal(raw.command("t12"), b"\a", "short frame")
            check_equal(raw.command("t123" + "9" + "00" * 9), b"\a", "DLC 9")
            check_equal(raw.command("t60784000100000000000"), b"z\r", "SDO upload of 1000 to node 7")
            check_equal(raw.read_answer(), b"t5878430010009201FFFF\r", "SDO answer after the acknowledgement")
            check_equal(raw.command(""), b"\r", "a bare CR")
            check_equal(raw.command("C"), b"\r", "close")
        finally:
            raw.close()
        server.stop()


def main():
    run_can_tests([test_slcan_sdo_and_nmt, test_slcan_and_socketcand_share_the_bus, test_slcan_adapter_commands,
                   test_slcan_pdo_sync_and_emcy, test_slcan_nmt_transitions,
                   test_slcan_store_and_restore_across_restart, test_slcan_lss_configure_and_fastscan])


if __name__ == "__main__":
    main()
