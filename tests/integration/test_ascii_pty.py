#!/usr/bin/python3
"""The TMCL ASCII interface over the pseudo-terminal of `motwin serve`, with pyserial as a
terminal program (or a script driving one) uses it.

Covers: command 139 (binary reply first, then lines), each echo mode of GP 67 (every character
as typed, the whole line after CR, no echo), typing character by character with backspace,
error statuses in the reply line, an over-long line and garbage followed by a good line, RUN and
STOP of a downloaded program, BIN back to binary frames, and GP 67 bit 0 (start in ASCII mode)
surviving a restart of the server on the same state directory.
"""

import os
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from motwin_harness import (  # noqa: E402
    GAP, SGP, Server, TempDir, check, check_equal, expect_reply, frame, run_tests,
)

ENTER_ASCII = 139
DOWNLOAD, END_DOWNLOAD = 132, 133
CALC, AGP, JA = 19, 35, 22


def expect_text(client, expected, what):
    data = client.read_exact(len(expected))
    check_equal(data.decode("latin-1"), expected, what)
    stray = client.read_available(0.05)
    check(stray == b"", f"{what}: unexpected bytes after it: {stray!r}")


def line(client, text, expected, what=None):
    client.send_raw(text.encode("latin-1"))
    expect_text(client, expected, what or repr(text))


def ascii_value(client, text):
    """The value of a reply line "BA 100 VALUE" to `text` (GP 67 = 32: no echo)."""
    client.send_raw(text.encode("latin-1"))
    reply = client.read_exact(len("BA 100 ")) + client.port.read_until(b"\r")
    check(reply.startswith(b"BA 100 ") and reply.endswith(b"\r"), f"reply to {text!r}: {reply!r}")
    return int(reply.decode().split()[2])


def enter_ascii(client):
    expect_reply(client.request(ENTER_ASCII), ENTER_ASCII, 100, 0, "139 (enter ASCII mode)")


def with_pty_server(motwin, body, state_dir=None):
    with TempDir() as tmp:
        link = os.path.join(tmp, "tmcm1636")
        server = Server(motwin, state_dir or os.path.join(tmp, "state"), tcp=False, pty_link=link)
        with server:
            with server.serial() as client:
                body(client)
            server.stop()


def test_echo_each_character(motwin):
    """GP 67 = 0 (factory): every character of an addressed line comes back as it is typed."""
    def body(client):
        enter_ascii(client)
        line(client, "AGAP 43, 0\r", "AGAP 43, 0\rBA 100 4000\r")
        # Typed slowly, with a typo corrected by backspace (and DEL, what most terminals send).
        for ch, echo in [("A", "A"), ("S", "S"), ("A", "A"), ("P", "P"), (" ", " "), ("4", "4"), ("4", "4"),
                         ("\b", "\b \b"), ("3", "3"), (",", ","), ("0", "0"), ("x", "x"), ("\x7f", "\b \b"),
                         (",", ","), (" ", " "), ("3", "3"), ("0", "0"), ("0", "0"), ("0", "0")]:
            line(client, ch, echo, f"echo of {ch!r}")
        line(client, "\r", "\rBA 100 3000\r", "CR after the edited SAP")
        line(client, "AGAP 43, 0\r", "AGAP 43, 0\rBA 100 3000\r", "the edited line was SAP 43, 0, 3000")
        # Lower case, tabs, CR LF.
        line(client, "a\tgap 43 0\r\n", "a gap 43 0\rBA 100 3000\r")  # a tab is stored and echoed as a blank
    with_pty_server(motwin, body)


def test_echo_whole_line(motwin):
    """GP 67 bit 4: nothing while typing, the edited line after CR, then the reply."""
    def body(client):
        enter_ascii(client)
        line(client, "ASGP 67, 0, 16\r", "ASGP 67, 0, 16\rBA 100 16\r", "switching the echo (echoed as typed)")
        client.send_raw(b"AGAP 43")
        check_equal(client.read_available(0.2), b"", "echo while typing in whole-line mode")
        client.send_raw(b"x\b, 0")
        check_equal(client.read_available(0.2), b"", "echo while typing in whole-line mode")
        line(client, "\r", "AGAP 43, 0\rBA 100 4000\r", "the whole edited line after CR")
    with_pty_server(motwin, body)


def test_no_echo(motwin):
    """GP 67 bit 5: only the reply (useful on RS485)."""
    def body(client):
        client.sgp(67, 0, 32)  # in binary, before entering ASCII mode
        enter_ascii(client)
        line(client, "AGAP 43, 0\r", "BA 100 4000\r")
        line(client, "ASAP 43, 0, 2500\rAGAP 43, 0\r", "BA 100 2500\rBA 100 2500\r", "two lines at once")
    with_pty_server(motwin, body)


def test_errors_and_resynchronisation(motwin):
    """Errors are answered with their status in the reply line; a bad or endless line never
    blocks the next one."""
    def body(client):
        client.sgp(67, 0, 32)
        enter_ascii(client)
        line(client, "AFOO 1, 2\r", "BA 2 0\r", "unknown mnemonic: status 2")
        line(client, "AGAP 43\r", "BA 4 0\r", "missing operand: status 4")
        line(client, "AGAP 43, 9\r", "BA 4 0\r", "motor out of range: status 4")
        line(client, "ASAP 43, 0, banana\r", "BA 4 0\r", "not a number: status 4")
        line(client, "AGAP 8, 0\r", "BA 3 0\r", "unknown parameter: status 3")
        line(client, "AJA 5\r", "BA 6 5\r", "program flow in direct mode: status 6")
        line(client, "A" + "X" * 5000 + "\r", "BA 2 0\r", "over-long line: status 2")
        line(client, "AGAP\x01\xff 43, 0\r", "BA 2 0\r", "control and 8-bit bytes in a line: status 2")
        line(client, "\x00\xff\xfe\x80garbage\r", "", "garbage not addressed to us: ignored")
        line(client, "BGAP 43, 0\r", "", "another module's line: ignored")
        line(client, "AGAP 43, 0\r", "BA 100 4000\r", "a good line after all that")
    with_pty_server(motwin, body)


def test_run_stop_and_bin(motwin):
    """RUN and STOP start and stop the stored program; BIN returns to binary frames."""
    def body(client):
        # Download a counter (binary): 0 CALC ADD 1, 1 AGP 0 bank 2, 2 JA 0.
        expect_reply(client.request(DOWNLOAD, 0, 0, 0), DOWNLOAD, 100, what="132")
        for command, type_, motor, value in [(CALC, 0, 0, 1), (AGP, 0, 2, 0), (JA, 0, 0, 0), (0, 0, 0, 0)]:
            expect_reply(client.request(command, type_, motor, value), command, 101, value, f"download {command}")
        expect_reply(client.request(END_DOWNLOAD), END_DOWNLOAD, 100, what="133")
        client.sgp(67, 0, 32)
        enter_ascii(client)
        line(client, "ARUN\r", "BA 100 0\r")
        line(client, "AGGP 128, 0\r", "BA 100 1\r", "application status after RUN: running")
        # 50 ms of the module's own time (GP 132, the tick timer): a loaded machine may run the
        # module slower than the wall clock.
        started_ms = ascii_value(client, "AGGP 132, 0\r")
        while ascii_value(client, "AGGP 132, 0\r") < started_ms + 50:
            time.sleep(0.005)
        line(client, "ASTOP\r", "BA 100 0\r")
        line(client, "AGGP 128, 0\r", "BA 100 0\r", "application status after STOP: stopped")
        count = ascii_value(client, "AGGP 0, 2\r")
        check(count > 0, f"the program counted while it ran: {count}")
        time.sleep(0.05)
        line(client, "AGGP 0, 2\r", f"BA 100 {count}\r", "nothing runs after STOP")
        # BIN, and a binary frame right behind it in the same write.
        client.send_raw(b"ABIN\r" + frame(GAP, 43))
        check_equal(client.read_exact(9), b"BA 100 0\r", "reply to BIN (still a line)")
        check_equal(client.read_exact(9), bytes.fromhex("02 01 64 06 00 00 0f a0 1c"), "binary GAP 43 after BIN")
    with_pty_server(motwin, body)


def test_start_in_ascii_mode_after_restart(motwin):
    """GP 67 bit 0 is stored (like every global parameter from 64 on): after a restart the pty
    starts in ASCII mode."""
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        link = os.path.join(tmp, "tmcm1636")
        with Server(motwin, state, tcp=False, pty_link=link) as server:
            with server.serial() as client:
                expect_reply(client.request(SGP, 67, 0, 0x21), SGP, 100, 0x21, "SGP 67 = start in ASCII, no echo")
                expect_reply(client.request(GAP, 43), GAP, 100, 4000, "still binary until 139 or a restart")
            server.stop()
        with Server(motwin, state, tcp=False, pty_link=link) as server:
            with server.serial() as client:
                line(client, "AGGP 67, 0\r", "BA 100 33\r", "ASCII from power-up")
                line(client, "ASGP 67, 0, 0\r", "BA 100 0\r")
                line(client, "AGAP 43, 0\r", "AGAP 43, 0\rBA 100 4000\r", "echo of each character now")
                line(client, "ABIN\r", "ABIN\rBA 100 0\r")
                expect_reply(client.request(GAP, 43), GAP, 100, 4000, "binary after BIN")
            server.stop()


if __name__ == "__main__":
    run_tests([test_echo_each_character, test_echo_whole_line, test_no_echo, test_errors_and_resynchronisation,
               test_run_stop_and_bin, test_start_in_ascii_mode_after_restart])
