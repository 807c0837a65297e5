#!/usr/bin/python3
"""SLCAN over TCP (`--can slcan-tcp:127.0.0.1:0`) with Debian's python3-can (`interface='slcan'`,
channel `socket://127.0.0.1:PORT`, the pyserial URL): NMT reset and boot-up, SDO expedited and
segmented, heartbeat, and one bus shared with a socketcand client (each sees the other's frames,
neither sees its own). Plus the adapter protocol by hand: version, status, errors for frames while
closed, bit rate change refused while open, garbage lines answered with BEL.
"""

import os
import socket
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import (  # noqa: E402
    NMT_RESET_NODE, STATE_BOOTUP, STATE_PREOP, CanServer, TestFailure, check, check_equal,
)
from motwin_harness import TempDir, run_tests  # noqa: E402

NODE = 7


def serve(tmp):
    return CanServer(MOTWIN, os.path.join(tmp, "state"), node_id=NODE,
                     can=("slcan-tcp:127.0.0.1:0", "socketcand:127.0.0.1:0"))


def test_slcan_sdo_and_nmt(motwin):
    with TempDir() as tmp, serve(tmp) as server, server.slcan_bus() as bus:
        bus.nmt(NMT_RESET_NODE, NODE)
        bus.wait_state(NODE, STATE_BOOTUP)
        check_equal(bus.upload_u(NODE, 0x1000, 0), 0xFFFC0192, "1000 over SLCAN")
        check_equal(bus.upload(NODE, 0x1008, 0), b"TMCM-3216", "1008 over SLCAN (segmented)")
        bus.download(NODE, 0x1017, 0, 50, 2)
        beats = bus.collect(0.5, lambda m: m.arbitration_id == 0x700 + NODE)
        check(8 <= len(beats) <= 12, f"{len(beats)} heartbeats in 0.5 s at 50 ms")
        check(all(bytes(m.data) == bytes([STATE_PREOP]) for m in beats), "heartbeat state")
        server.stop()


def test_slcan_and_socketcand_share_the_bus(motwin):
    with TempDir() as tmp, serve(tmp) as server, server.slcan_bus() as slcan, server.bus() as socketcand:
        socketcand.drain(0.1)
        slcan.send(0x321, [9, 8, 7])
        msg = socketcand.receive(lambda m: m.arbitration_id == 0x321, 1.0, "SLCAN frame at the socketcand client")
        check_equal(bytes(msg.data), b"\x09\x08\x07", "data")
        socketcand.send(0x322, [1])
        msg = slcan.receive(lambda m: m.arbitration_id == 0x322, 1.0, "socketcand frame at the SLCAN client")
        check_equal(bytes(msg.data), b"\x01", "data")
        check_equal(slcan.collect(0.3, lambda m: m.arbitration_id == 0x321), [], "own frame echoed over SLCAN")
        server.stop()


class RawSlcan:
    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        self.buffer = b""

    def command(self, text, timeout=2.0):
        """Sends one line; returns the answer up to and including the first CR or BEL."""
        self.sock.sendall(text.encode("ascii") + b"\r")
        return self.read_answer(timeout, text)

    def read_answer(self, timeout=2.0, text="(nothing sent)"):
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
    with TempDir() as tmp, serve(tmp) as server:
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
            check_equal(raw.read_answer(), b"t5878430010009201FCFF\r", "SDO answer after the acknowledgement")
            check_equal(raw.command(""), b"\r", "a bare CR")
            check_equal(raw.command("C"), b"\r", "close")
        finally:
            raw.close()
        server.stop()


def main():
    global MOTWIN
    import motwin_harness
    args = motwin_harness.parse_arguments()
    MOTWIN = os.path.abspath(args.motwin)
    run_tests([test_slcan_sdo_and_nmt, test_slcan_and_socketcand_share_the_bus, test_slcan_adapter_commands])


MOTWIN = None

if __name__ == "__main__":
    main()
