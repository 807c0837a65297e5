#!/usr/bin/python3
"""TMCL over CAN on the TMCM-1636 (`--can socketcand:...`, `slcan-tcp:...`, `slcan:LINK`) with
Debian's python3-can: 7- and 8-byte requests and their reply layout, the version string, short
frames, GP 70/71 taking effect at once, GP 69 at the next reset, command 138's delayed reply
over CAN while TMCL over TCP runs beside it.
"""

import os
import struct
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from can_bus_harness import BusServer, TmclCan, check, check_equal, collect, open_bus, receive  # noqa: E402
from motwin_harness import FRAME_TIMEOUT, TcpClient, TempDir, run_tests  # noqa: E402


def serve(motwin, tmp, *extra):
    return BusServer(motwin, os.path.join(tmp, "state"),
                     ["--module", "tmcm-1636", "--can", "socketcand:127.0.0.1:0", *extra])


def test_seven_and_eight_byte_requests(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server:
        bus = open_bus(server.port())
        try:
            tmcl = TmclCan(bus)
            # GGP 71 bank 0: reply ID 2, data = receive ID, status, command, value (big-endian).
            check_equal(tmcl.request_raw([10, 71, 0, 0, 0, 0, 0]), bytes([1, 100, 10, 0, 0, 0, 1]), "7-byte reply")
            # SGP user variable 3 (bank 2) with PyTrinamic's 8th byte; the reply has 8 bytes, padded with 0.
            check_equal(tmcl.request_raw([9, 3, 2, 0x12, 0x34, 0x56, 0x78, 0xEE]),
                        bytes([1, 100, 9, 0x12, 0x34, 0x56, 0x78, 0]), "8-byte reply")
            check_equal(tmcl.ok(10, 3, 2, length=8), 0x12345678, "GGP of the variable written over CAN")
            check_equal(tmcl.request(10, 3, 2, length=7)[3:7], bytes([0x12, 0x34, 0x56, 0x78]), "7-byte GGP")
            # Errors as over serial: unknown command 2, wrong type 3, motor out of range 4.
            check_equal(tmcl.request(99)[1], 2, "status of an unknown command")
            check_equal(tmcl.request(6, 250)[1], 3, "status of an unknown axis parameter")
            check_equal(tmcl.request(6, 4, 7)[1], 4, "status of a bad motor")
            # A frame too short for a request: status 2 with its command byte, nothing changes.
            check_equal(tmcl.request_raw([9, 3, 2, 0]), bytes([1, 2, 9, 0, 0, 0, 0]), "short frame")
            check_equal(tmcl.ok(10, 3, 2), 0x12345678, "variable after the short frame")
            # Frames on other IDs are not the module's.
            tmcl.send_raw([10, 71, 0, 0, 0, 0, 0], can_id=5)
            check_equal(collect(bus, 0.3, lambda m: m.arbitration_id == 2), [], "reply to another ID")
        finally:
            bus.shutdown()
        server.stop()


def test_version_string_and_binary_version(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server:
        bus = open_bus(server.port())
        try:
            tmcl = TmclCan(bus)
            check_equal(tmcl.request_raw([136, 0, 0, 0, 0, 0, 0]), b"1636V109", "version string, 7-byte request")
            check_equal(tmcl.request_raw([136, 0, 0, 0, 0, 0, 0, 0]), b"1636V109", "version string, 8-byte request")
            check_equal(tmcl.ok(136, 1), 0x06640109, "binary version")
            check_equal(tmcl.request(139)[1], 6, "ASCII mode is not available over CAN")
        finally:
            bus.shutdown()
        server.stop()


def test_can_ids_take_effect_at_once_and_are_stored(motwin):
    # At once, then across a restart (GP 70/71 are stored automatically).
    with TempDir() as tmp:
        with serve(motwin, tmp) as server:
            bus = open_bus(server.port())
            try:
                tmcl = TmclCan(bus)
                tmcl.send_raw([9, 70, 0, 0, 0, 0, 0x55])
                msg = receive(bus, lambda m: m.arbitration_id in (2, 0x55), FRAME_TIMEOUT, "reply to SGP 70")
                check_equal(msg.arbitration_id, 0x55, "the reply to SGP 70 uses the new send ID")
                check_equal(bytes(msg.data), bytes([1, 100, 9, 0, 0, 0, 0x55]), "reply to SGP 70")
                tmcl.send_id = 0x55
                check_equal(tmcl.request(9, 71, 0, 0x33)[0], 0x33, "module byte of the reply to SGP 71")
                tmcl.send_raw([10, 71, 0, 0, 0, 0, 0], can_id=1)
                check_equal(collect(bus, 0.3, lambda m: m.arbitration_id == 0x55), [], "reply on the old receive ID")
                tmcl.receive_id = 0x33
                check_equal(tmcl.ok(10, 71), 0x33, "GGP 71 on the new receive ID")
            finally:
                bus.shutdown()
            server.stop()
        with serve(motwin, tmp) as server:
            bus = open_bus(server.port())
            try:
                check_equal(TmclCan(bus, 0x33, 0x55).ok(10, 70), 0x55, "GP 70 after a restart")
            finally:
                bus.shutdown()
            server.stop()


def test_bit_rate_applies_after_a_reset(motwin):
    with TempDir() as tmp, serve(motwin, tmp, "--can-bitrate", "500k", "--tmcl-tcp", "127.0.0.1:0") as server:
        bus = open_bus(server.port())
        try:
            tmcl = TmclCan(bus)
            tmcl.send_raw([136, 1, 0, 0, 0, 0, 0])
            check_equal(collect(bus, 0.3), [], "frames from a module set to 1 Mbit/s on a 500 kbit/s bus")
            with TcpClient(server.tcp_port_of()) as tcp:
                tcp.ok(9, 69, 0, 7)      # SGP 69 = 500 kbit/s: stored, not active yet
                tmcl.send_raw([136, 1, 0, 0, 0, 0, 0])
                check_equal(collect(bus, 0.3), [], "frames before the reset")
                tcp.ok(255, 0, 0, 1234)  # software reset: the controller starts at 500 kbit/s
            check_equal(tmcl.ok(136, 1), 0x06640109, "binary version after the reset")
        finally:
            bus.shutdown()
        server.stop()


def test_delayed_138_reply_over_can_beside_tcp(motwin):
    with TempDir() as tmp, serve(motwin, tmp, "--tmcl-tcp", "127.0.0.1:0") as server:
        bus = open_bus(server.port())
        try:
            tmcl = TmclCan(bus, length=8)
            tmcl.ok(4, 0, 0, 2000)                 # MVP ABS 2000
            check_equal(tmcl.request(138, 0, 0, 1), bytes([1, 100, 138, 0, 0, 0, 1, 0]), "immediate reply to 138")
            event = receive(bus, lambda m: m.arbitration_id == 2, 10.0, "the delayed 138 reply")
            check_equal(bytes(event.data), bytes([1, 128, 138, 0, 0, 0, 1, 0]), "delayed reply: status 128, 8 bytes")
            with TcpClient(server.tcp_port_of()) as tcp:
                check_equal(tcp.version_string(), b"1636V109", "TMCL over TCP beside CAN")
                check_equal(tcp.ggp(3, 2), 0, "user variable over TCP")
        finally:
            bus.shutdown()
        server.stop()


def test_slcan_tcp_and_pty(motwin):
    with TempDir() as tmp:
        link = os.path.join(tmp, "slcan0")
        with BusServer(motwin, os.path.join(tmp, "state"),
                       ["--module", "tmcm-1636", "--can", "slcan-tcp:127.0.0.1:0", "--can", f"slcan:{link}"]) as server:
            check_equal(server.endpoints["can-slcan-pty"][0][0], link, "pty endpoint line names the link")
            check(os.path.realpath(link).startswith("/dev/pts/"), f"{link} -> {os.path.realpath(link)}")
            over_tcp = open_bus(server.port("can-slcan-tcp"), interface="slcan")
            over_pty = open_bus(None, interface="slcan", channel=link)
            try:
                check_equal(TmclCan(over_tcp).request_raw([136, 0, 0, 0, 0, 0, 0]), b"1636V109", "version over SLCAN/TCP")
                check_equal(TmclCan(over_pty).request_raw([136, 0, 0, 0, 0, 0, 0, 0]), b"1636V109",
                            "version over SLCAN on the pty")
                # The pty client also sees the TCP client's request and its reply: one bus.
                collect(over_pty, 0.2)
                TmclCan(over_tcp).send_raw([10, 71, 0, 0, 0, 0, 0])
                msg = receive(over_pty, lambda m: m.arbitration_id == 1, FRAME_TIMEOUT,
                              "the TCP client's request on the pty")
                check_equal(bytes(msg.data), bytes([10, 71, 0, 0, 0, 0, 0]), "request seen on the pty")
                reply = receive(over_pty, lambda m: m.arbitration_id == 2, FRAME_TIMEOUT,
                                "the module's reply on the pty")
                check_equal(bytes(reply.data), bytes([1, 100, 10, 0, 0, 0, 1]), "reply seen on the pty")
            finally:
                over_tcp.shutdown()
                over_pty.shutdown()
            server.stop()
        check(not os.path.lexists(link), "the pty link is removed at shutdown")


if __name__ == "__main__":
    run_tests([test_seven_and_eight_byte_requests, test_version_string_and_binary_version,
               test_can_ids_take_effect_at_once_and_are_stored, test_bit_rate_applies_after_a_reset,
               test_delayed_138_reply_over_can_beside_tcp, test_slcan_tcp_and_pty])
