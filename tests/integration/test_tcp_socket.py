#!/usr/bin/python3
"""TMCL over the TCP endpoint of `motwin serve` with a plain socket (as PyTrinamic's
socket_serial_tmcl interface sends it: 9-byte frames back to back).

The same checks as over the pty (tmcl_checks.py), each on a fresh real-time server, plus:
requests pipelined in one send() are answered in order; a frame for another module address gets
no reply and the next good frame still works; two connections see the same module; an MVP
from rest approaches its target monotonically and never passes it (AP 52 polled as fast as the
connection allows).
"""

import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import tmcl_checks  # noqa: E402
from motwin_harness import (  # noqa: E402
    BANK_USER, FRAME_LENGTH, GAP, GET_VERSION, GGP, SAP, SGP, STATUS_OK, STATUS_WRONG_TYPE, Server, TempDir, check,
    check_equal, expect_reply, frame, parse_reply, run_tests,
)


def run_on_tcp(motwin, check_function):
    with TempDir() as tmp:
        with Server(motwin, os.path.join(tmp, "state")) as server:
            with server.tcp() as client:
                check_function(client)
            server.stop()


def make_test(check_function):
    def test(motwin):
        run_on_tcp(motwin, check_function)
    test.__name__ = check_function.__name__.replace("check_", "test_tcp_")
    return test


def test_tcp_pipelined(motwin):
    """Many requests in one send(): one reply each, in order."""
    with TempDir() as tmp:
        with Server(motwin, os.path.join(tmp, "state")) as server:
            with server.tcp() as c:
                requests = []
                expected = []
                for i in range(40):
                    requests.append(frame(SGP, i, BANK_USER, 1000 + i))
                    expected.append((SGP, STATUS_OK, 1000 + i))
                    requests.append(frame(GGP, i, BANK_USER))
                    expected.append((GGP, STATUS_OK, 1000 + i))
                requests.append(frame(SAP, 43, 0, 2500))
                expected.append((SAP, STATUS_OK, 2500))
                requests.append(frame(GAP, 43))
                expected.append((GAP, STATUS_OK, 2500))
                requests.append(frame(GAP, 99))  # unknown: status 3, still in order
                expected.append((GAP, STATUS_WRONG_TYPE, 0))
                requests.append(frame(GET_VERSION, 1))
                expected.append((GET_VERSION, STATUS_OK, 0x06640109))
                c.send_raw(b"".join(requests))
                raw = c.read_exact(FRAME_LENGTH * len(expected), timeout=10.0)
                for i, (command, status, value) in enumerate(expected):
                    r = parse_reply(raw[i * FRAME_LENGTH:(i + 1) * FRAME_LENGTH])
                    expect_reply(r, command, status, value, f"pipelined reply {i}")
                c.expect_no_reply(0.2, "after the pipelined replies")
                # Version string in the middle of a pipeline: 9 bytes without checksum.
                c.send_raw(frame(GAP, 43) + frame(GET_VERSION, 0) + frame(GAP, 43))
                raw = c.read_exact(27, timeout=5.0)
                expect_reply(parse_reply(raw[:9]), GAP, STATUS_OK, 2500, "GAP before the version")
                check_equal(raw[9:18], b"\x021636V109", "version string in a pipeline")
                expect_reply(parse_reply(raw[18:]), GAP, STATUS_OK, 2500, "GAP after the version")
            server.stop()


def test_tcp_other_address(motwin):
    with TempDir() as tmp:
        with Server(motwin, os.path.join(tmp, "state")) as server:
            with server.tcp() as c:
                for address in (0, 2, 3, 255):
                    c.send_raw(frame(SAP, 43, 0, 1500, address=address))
                    c.expect_no_reply(0.3, f"SAP for module address {address}")
                    check_equal(c.gap(43), 4000, f"AP 43 after a SAP for address {address}")
                # A bad checksum for another address: silence too (the frame is not ours).
                bad = bytearray(frame(GAP, 43, address=5))
                bad[8] ^= 0xFF
                c.send_raw(bytes(bad))
                c.expect_no_reply(0.3, "bad-checksum frame for address 5")
                # Other-address frame pipelined with ours: only ours is answered.
                c.send_raw(frame(GAP, 43, address=7) + frame(GAP, 44))
                expect_reply(parse_reply(c.read_exact(9)), GAP, STATUS_OK, 2000, "GAP 44 after a foreign frame")
                c.expect_no_reply(0.2, "after the foreign + own pipeline")
            server.stop()


def test_tcp_two_connections(motwin):
    """Two connections talk to the same module; closing one leaves the other working."""
    with TempDir() as tmp:
        with Server(motwin, os.path.join(tmp, "state")) as server:
            a = server.tcp()
            b = server.tcp()
            try:
                a.sap(43, 3333)
                check_equal(b.gap(43), 3333, "AP 43 seen from the second connection")
                b.sgp(3, BANK_USER, -5)
                check_equal(a.ggp(3, BANK_USER), -5, "user variable 3 seen from the first connection")
                a.close()
                check_equal(b.gap(43), 3333, "second connection after the first closed")
                c = server.tcp()
                check_equal(c.gap(43), 3333, "a new connection")
                c.close()
            finally:
                a.close()
                b.close()
            server.stop()


if __name__ == "__main__":
    run_tests([make_test(f) for f in tmcl_checks.COMMON_CHECKS]
              + [make_test(tmcl_checks.check_mvp_no_overshoot), test_tcp_pipelined, test_tcp_other_address, test_tcp_two_connections])
