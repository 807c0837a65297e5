#!/usr/bin/python3
"""TMCL over the pseudo-terminal of `motwin serve`, with pyserial as host software uses it.

Each check runs on a fresh server (empty state directory, real-time pacing) reached through
`serial.Serial(link, 115200, timeout=1)`: version (136 type 0/1), manual frames, SAP/GAP/STAP/
RSAP and user variables, ROR/ROL/MST ramps (AP 42), MVP ABS/REL until AP 55 = 1 and AP 52 is the
exact target, software reset 255 (stored values survive, unstored ones drop), checksum errors.
Also: the pty can be closed and reopened; after a host flooded requests without reading and
closed the port, the next opener gets exactly the reply to its own request.
"""

import os
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import tmcl_checks  # noqa: E402
from motwin_harness import (  # noqa: E402
    GAP, SGP, Server, TempDir, check, check_equal, expect_reply, frame, run_tests,
)


def run_on_pty(motwin, check_function):
    with TempDir() as tmp:
        link = os.path.join(tmp, "tmcm1636")
        server = Server(motwin, os.path.join(tmp, "state"), tcp=False, pty_link=link)
        with server:
            check_equal(server.pty_link, link, "pty link in the endpoint line")
            check(os.path.realpath(link) == server.pty_device, f"{link} should point to {server.pty_device}")
            with server.serial() as client:
                check_function(client)
            server.stop()


def make_test(check_function):
    def test(motwin):
        run_on_pty(motwin, check_function)
    test.__name__ = check_function.__name__.replace("check_", "test_pty_")
    return test


def test_pty_reopen(motwin):
    """Closing and reopening the pty (a host application restarting) keeps it working."""
    with TempDir() as tmp:
        link = os.path.join(tmp, "tmcm1636")
        with Server(motwin, os.path.join(tmp, "state"), tcp=False, pty_link=link) as server:
            for round_ in range(3):
                with server.serial() as client:
                    client.sap(43, 1000 + round_)
                    check_equal(client.gap(43), 1000 + round_, f"AP 43 in round {round_}")
                    # Leave a half frame behind: the next opener must not be confused by it
                    # (it pauses longer than the resync gap, 5 ms, from when the server read it:
                    # the server counts only the silence it saw itself).
                    read_before = server.bytes_read()
                    client.send_raw(frame(GAP, 43)[:4])
                    server.wait_until_read(read_before + 4)
                time.sleep(0.2)  # 40 x the resync gap: a poll of the server starts in it
            with server.serial() as client:
                expect_reply(client.request(GAP, 43), GAP, 100, 1002, "GAP 43 after reopening")
            server.stop()


def test_pty_reopen_after_unread_flood(motwin):
    """A host that sent many requests without reading the replies and closed the port (it
    crashed, or gave up): the next host opens the port (pyserial flushes its input on open) and
    must get the reply to its own request, frame-aligned, with no stale bytes behind it."""
    import serial
    with TempDir() as tmp:
        link = os.path.join(tmp, "tmcm1636")
        with Server(motwin, os.path.join(tmp, "state"), tcp=False, pty_link=link) as server:
            flooder = serial.Serial(link, 115200, timeout=1)
            try:
                flood = frame(SGP, 20, 2, 5) * 3000  # 27 000 bytes of replies nobody reads
                read_before = server.bytes_read()
                flooder.write(flood)
                flooder.flush()
                # The server takes in no more requests than it has queue room for: once it has
                # read the flood, at most its queue's worth (32) is left to answer.
                server.wait_until_read(read_before + len(flood))
                time.sleep(0.5)
            finally:
                flooder.close()
            time.sleep(0.1)
            with server.serial() as c:
                raw = c.request_raw(frame(GAP, 43))
                stale = c.read_available(0.3)
                check(raw == bytes.fromhex("02 01 64 06 00 00 0f a0 1c") and stale == b"",
                      f"after reopening: first 9 bytes {raw.hex(' ')} (expected the GAP 43 reply "
                      f"02 01 64 06 00 00 0f a0 1c), then {len(stale)} more bytes")
            server.stop()


if __name__ == "__main__":
    run_tests([make_test(f) for f in tmcl_checks.COMMON_CHECKS] + [test_pty_reopen, test_pty_reopen_after_unread_flood])
