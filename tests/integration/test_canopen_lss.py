#!/usr/bin/python3
"""LSS (CiA-305) slave of the TMCM-3216 over the socketcand server, raw frames on Debian's
python3-can (0x7E5 master, 0x7E4 slave): switch state global and selective, inquire identity and
node ID, configure node ID and bit timing with their error codes, store configuration and the new
node ID after NMT reset communication and after a restart of the server; an unconfigured node
(2705 = 255) that answers nothing but LSS, found by python-canopen's fastscan, configured, stored,
and booting with its new ID when switched back to waiting.
"""

import os
import struct
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import (  # noqa: E402
    NMT_RESET_COMM, SAVE, STATE_BOOTUP, CanServer, check_equal, run_can_tests,
)
from motwin_harness import TempDir  # noqa: E402


def serve(motwin, tmp, *extra_args):
    # No --node-id: the stored node ID (2705) decides, as LSS needs.
    return CanServer(motwin, os.path.join(tmp, "state"), extra_args=extra_args)


def identity(bus, node):
    return [bus.upload_u(node, 0x1018, sub) for sub in (1, 2, 3, 4)]


def switch_selective(bus, ident):
    for command, value in zip((0x40, 0x41, 0x42), ident[:3]):
        check_equal(bus.lss_silent([command] + list(struct.pack("<I", value)), wait=0.05), [],
                    f"answer to {command:#04x}")
    check_equal(bus.lss([0x43] + list(struct.pack("<I", ident[3]))), bytes([0x44]) + bytes(7), "selective answer")


def test_inquire_configure_store_and_restart(motwin):
    with TempDir() as tmp:
        # A bus without bit timing: the node stays reachable when its stored 125 kbit/s applies at
        # the reset (on a timed bus it would be cut off: test_can_bitrate.py).
        with serve(motwin, tmp, "--can-bitrate", "0") as server, server.bus() as bus:
            ident = identity(bus, 1)
            check_equal(bus.lss_silent([0x5E]), [], "inquire in waiting state")
            switch_selective(bus, ident)
            for command, value in zip((0x5A, 0x5B, 0x5C, 0x5D), ident):
                answer = bus.lss([command])
                check_equal((answer[0], struct.unpack_from("<I", answer, 1)[0]), (command, value), "inquire identity")
            check_equal(bus.lss([0x5E])[:2], bytes([0x5E, 1]), "inquire node ID")
            check_equal(bus.lss([0x11, 200])[:2], bytes([0x11, 1]), "configure node ID 200: out of range")
            check_equal(bus.lss([0x11, 23])[:2], bytes([0x11, 0]), "configure node ID 23")
            check_equal(bus.lss([0x13, 0, 8])[:2], bytes([0x13, 1]), "10 kbit/s: not supported")
            check_equal(bus.lss([0x13, 0, 4])[:2], bytes([0x13, 0]), "125 kbit/s")
            check_equal(bus.lss([0x17])[:2], bytes([0x17, 0]), "store configuration")
            bus.lss([0x04, 0x00], answer=False)  # back to waiting
            check_equal(bus.upload_u(1, 0x2708, 0), 1, "still node 1 before the reset")
            bus.nmt(NMT_RESET_COMM, 1)
            bus.wait_state(23, STATE_BOOTUP)
            check_equal(bus.upload_u(23, 0x2708, 0), 23, "2708 after reset communication")
            check_equal(bus.upload_u(23, 0x2705, 0), 23, "2705 stored by LSS")
            check_equal(bus.upload_u(23, 0x2704, 0), 125, "2704 stored by LSS")
            server.stop()
        with serve(motwin, tmp, "--can-bitrate", "125k") as server, server.bus() as bus:
            check_equal(bus.upload_u(23, 0x2708, 0), 23, "node ID after a restart")
            check_equal(bus.upload_u(23, 0x2707, 0), 125, "bit rate after a restart")
            server.stop()


def test_unconfigured_node_fastscan_configure_and_boot(motwin):
    with TempDir() as tmp:
        with serve(motwin, tmp) as server, server.bus() as bus, server.bus() as listener:
            ident = identity(bus, 1)
            check_equal(bus.lss_fastscan(listener), None, "fastscan of a configured node")
            bus.download(1, 0x2705, 0, 255, 1)
            bus.download(1, 0x2706, 1, SAVE, 4)
            server.stop()
        with serve(motwin, tmp) as server, server.bus() as bus, server.bus() as listener:
            bus.nmt(NMT_RESET_COMM, 0)
            bus.send(0x601, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0])
            check_equal(bus.collect(0.3, lambda m: m.arbitration_id != 0x7E4), [], "frames of an unconfigured node")
            check_equal(bus.lss_fastscan(listener), ident, "identity found by fastscan")
            check_equal(bus.lss([0x5E])[:2], bytes([0x5E, 255]), "inquire node ID: unconfigured")
            check_equal(bus.lss([0x11, 20])[:2], bytes([0x11, 0]), "configure node ID 20")
            check_equal(bus.lss([0x17])[:2], bytes([0x17, 0]), "store configuration")
            bus.lss([0x04, 0x00], answer=False)
            msg = bus.wait_state(20, STATE_BOOTUP)
            check_equal(bytes(msg.data), b"\0", "boot-up of the newly configured node")
            check_equal(bus.upload_u(20, 0x1000, 0), 0xFFFF0192, "SDO to the new node ID")
            server.stop()
        with serve(motwin, tmp) as server, server.bus() as bus:
            check_equal(bus.upload_u(20, 0x2708, 0), 20, "stored node ID after a restart")
            server.stop()


def main():
    run_can_tests([
        test_inquire_configure_store_and_restart,
        test_unconfigured_node_fastscan_configure_and_boot,
    ])


if __name__ == "__main__":
    main()
