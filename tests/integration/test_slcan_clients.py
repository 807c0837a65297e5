#!/usr/bin/python3
"""Misbehaving clients and floods on the SLCAN adapter of a pseudo-terminal (`--can slcan:LINK`),
with a TMCM-3216 (node 5) on the bus and a well-behaved socketcand client beside it that loops
SDO downloads and uploads of 1017 and checks every answer.

- Garbage: 64 KiB of lines no command starts with get one BEL each, exactly, and the session
  goes on (open channel, version, flags); a line of 10 000 characters costs one BEL.
- A client writing a byte every 5 ms gets the same answers as one writing whole lines (version,
  an SDO upload of 1000 acknowledged `z` and answered by the node).
- A client that leaves in the middle of a line: the adapter keeps the half line, as a USB dongle
  does; the next client's first CR costs exactly one BEL and the session goes on.
- Flood: 8 000 SDO uploads (at most 256 unanswered at a time, the client reading as it writes)
  each acknowledged and answered, exactly, while the socketcand client keeps its rounds; then
  20 000 more from a client that never reads: the adapter drops what piles up beyond its bound
  (logged), and a client that flushes its input, as pyserial does on open, gets only fresh
  answers. The server's resident memory stays within a fixed bound over its idle figure
  (client_harness.Memory).
"""

import os
import random
import re
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from can_bus_harness import BusServer  # noqa: E402
from client_harness import (  # noqa: E402
    ANSWER_1000, SLCAN_UNIT_ENDS, UPLOAD_1000, Memory, UnitPty, Worker, is_slcan_frame, run_beside, sdo_1017_round,
    sdo_answer_of, slcan_answer, slcan_line, slcan_open, socketcand_client, socketcand_frame, write_and_read_some,
)
from motwin_harness import TempDir, TestFailure, check, check_equal, run_tests  # noqa: E402

NODE = 5
SLCAN_UPLOAD_1000 = slcan_line(0x600 + NODE, UPLOAD_1000) + "\r"
SLCAN_ANSWER_1000 = slcan_line(0x580 + NODE, ANSWER_1000) + "\r"
SLCAN_COMMAND_LETTERS = b"OLCSsVNFZtTrR\r\n\0"
# The windowed flood runs in a thread of this process, so the socketcand client beside it competes
# for the interpreter lock and may read nothing until the flood ends (seen in CI: the flood took
# 0.3 s). Every flood request puts two frames of about 45 bytes on that client's connection, so
# 8 000 requests (0.72 MB) stay below what the server holds for a slow reader (1 MiB, beyond which
# it closes the connection, as it should) even when the client reads nothing meanwhile.
WINDOWED_FLOOD_REQUESTS = 8_000
FLOOD_REQUESTS = 20_000
FLOOD_WINDOW = 256
# What else the flooding pty client sees: the socketcand client's SDO exchange and the heartbeats it sets.
BESIDE_THE_FLOOD = (f"t{0x600 + NODE:03X}8", f"t{0x580 + NODE:03X}8", f"t{0x700 + NODE:03X}1")


def serve(motwin, tmp):
    link = os.path.join(tmp, "slcan0")
    args = ["--module", "tmcm-3216", "--node-id", str(NODE), "--can", "socketcand:127.0.0.1:0",
            "--can", f"slcan:{link}"]
    return BusServer(motwin, os.path.join(tmp, "state"), args), link


def is_stale_tail(unit):
    """The end of a frame line that was in the pty when a new client opened it and flushed its
    input: the kernel lets such bytes through now and then (about 1 open in 30 while frames flow,
    whatever the server does), so a client's first answer is looked for behind them."""
    return len(unit) > 1 and unit.endswith("\r") and all(ch in "0123456789ABCDEF" for ch in unit[:-1])


def is_transmit_ack(unit):
    """`z\r` / `Z\r`: the adapter's acknowledgement of a `t`/`T` command."""
    return unit in ("z\r", "Z\r")


def is_well_formed_frame(unit):
    """A whole SLCAN frame line: t/r with 3 hex digits of ID, T/R with 8, a DLC digit, as many
    data bytes as it says (none for r/R), CR."""
    match = re.fullmatch(r"(?:[tr][0-9A-F]{3}|[TR][0-9A-F]{8})([0-8])([0-9A-F]*)\r", unit)
    if match is None:
        return False
    return len(match.group(2)) == (0 if unit[0] in "rR" else 2 * int(match.group(1)))


def behind_stale_bytes(unit):
    """What follows the stale bytes a unit may start with: the tail of a frame (hex digits, maybe
    its letter) that the kernel let through a flush runs into the next unit, so that a client's
    first answer can arrive as `t705V1013\r` or `17FV1013\r`. A well-formed frame, a bare stale
    tail (only hex, then CR) and a unit without such a start are returned as they are."""
    if is_well_formed_frame(unit) or is_stale_tail(unit):
        return unit
    match = re.match(r"[tTrR]?[0-9A-F]+", unit)
    if match is None or unit[match.end():] == "\r":
        return unit
    return unit[match.end():]


def first_answer_after_open(c, after_transmits=False, server=None, timeout=5.0):
    """The first answer behind the stale frames and tails. `after_transmits`: the client sent
    transmit commands before it flushed, so whole acknowledgements may slip through the flush like
    the frames do (seen on a loaded machine). A failure lists what was passed over and the end
    of the server's stderr."""
    passed_over = []
    deadline = time.monotonic() + timeout
    try:
        while True:
            unit = behind_stale_bytes(c.read_unit(max(0.01, deadline - time.monotonic())))
            if is_slcan_frame(unit) or is_stale_tail(unit) or (after_transmits and is_transmit_ack(unit)):
                passed_over.append(unit)
                check(time.monotonic() < deadline, f"no SLCAN answer within {timeout} s")
                continue
            return unit
    except TestFailure as failure:
        stderr = server.stderr_lines()[-5:] if server is not None else "not captured"
        odd = [u for u in passed_over if not (is_well_formed_frame(u) or is_transmit_ack(u))]
        raise TestFailure(f"{failure}; passed over {len(passed_over)} units, the first {passed_over[:5]!r}, "
                          f"the last {passed_over[-5:]!r}, neither whole frames nor acknowledgements: {odd[:10]!r}; "
                          f"server stderr ends {stderr!r}") from None


def garbage_lines(rng, total):
    """Lines of random bytes whose first byte starts no SLCAN command (each is one BEL)."""
    first_bytes = bytes(b for b in range(256) if b not in SLCAN_COMMAND_LETTERS)
    lines = []
    size = 0
    while size < total:
        body = bytes(b for b in (rng.randrange(256) for _ in range(rng.randrange(120))) if b != 0x0D)
        lines.append(bytes([rng.choice(first_bytes)]) + body + b"\r")
        size += len(lines[-1])
    return lines


def pty_misbehaving_client(link):
    c = slcan_open(UnitPty(link, SLCAN_UNIT_ENDS))
    try:
        lines = garbage_lines(random.Random(1013), 65536)
        c.send(b"".join(lines))
        answers = [slcan_answer(c) for _ in lines]
        check_equal(answers.count("\a"), len(lines), f"BELs for {len(lines)} garbage lines ({set(answers)!r})")
        c.send("x" * 10000 + "\r")
        check_equal(slcan_answer(c), "\a", "one BEL for a line of 10 000 characters")
        for command, answer in (("V", "V1013\r"), ("F", "F00\r"), ("N", "NMOTW\r")):
            c.send(command + "\r")
            check_equal(slcan_answer(c), answer, f"{command} after the garbage")
        # A byte every 5 ms: the same answers.
        c.send_slowly("V\r", pause=0.005)
        check_equal(slcan_answer(c), "V1013\r", "version typed slowly")
        c.send_slowly(SLCAN_UPLOAD_1000, pause=0.005)
        check_equal(slcan_answer(c), "z\r", "SDO upload typed slowly: acknowledged")
        c.read_until(lambda u: u == SLCAN_ANSWER_1000, what="the node's answer to the slow upload")
        # Leave in the middle of a line.
        c.send("t605")
    finally:
        c.close()
    c = UnitPty(link, SLCAN_UNIT_ENDS)
    try:
        c.send("\r")
        check_equal(first_answer_after_open(c), "\a", "the half line the last client left, ended by our CR")
        c.send("V\r")
        check_equal(slcan_answer(c), "V1013\r", "version after the half line")
        c.send(SLCAN_UPLOAD_1000)
        check_equal(slcan_answer(c), "z\r", "SDO upload acknowledged")
        c.read_until(lambda u: u == SLCAN_ANSWER_1000, what="the node's answer")
    finally:
        c.close()
    return f"{len(lines)} garbage lines, one BEL each; slow lines; a half line left behind"


def test_slcan_pty_garbage_and_slow_clients(motwin):
    with TempDir() as tmp:
        server, link = serve(motwin, tmp)
        with server:
            good = socketcand_client(server.port())
            try:
                rounds = run_beside([Worker(pty_misbehaving_client, link)], lambda i: sdo_1017_round(good, NODE, i),
                                    min_rounds=20, timeout=60.0, what="SLCAN pty clients")
                print(f"  well-behaved socketcand client: {rounds} rounds of download + upload", flush=True)
            finally:
                good.close()
            check(server.alive(), "server died")
            server.stop()


def windowed_flood(link, count, window):
    """Sends `count` SDO uploads of 1000 through the pty, at most `window` unanswered, reading
    whatever comes as it writes; checks that each is acknowledged and answered exactly once."""
    c = slcan_open(UnitPty(link, SLCAN_UNIT_ENDS))
    try:
        request = SLCAN_UPLOAD_1000.encode("latin-1")
        pending = b""
        sent = acks = answers = 0
        others = {}
        deadline = time.monotonic() + 120.0
        while answers < count:
            check(time.monotonic() < deadline, f"pty flood: {answers} of {count} answers after 120 s")
            if not pending and sent < count and sent - answers < window:
                batch = min(count - sent, window - (sent - answers), 64)
                pending = request * batch
                sent += batch
            pending, received = write_and_read_some(c.fd, pending)
            if received:
                c.feed(received)
                while (unit := c.pop_unit()) is not None:
                    if unit == "z\r":
                        acks += 1
                    elif unit == SLCAN_ANSWER_1000:
                        answers += 1
                    else:
                        check(unit.startswith(BESIDE_THE_FLOOD), f"pty flood: unexpected {unit!r}")
                        others[unit[:4]] = others.get(unit[:4], 0) + 1
        check_equal((acks, answers), (count, count), "pty flood: acknowledgements and answers")
    finally:
        c.close()
    return f"{count} SDO uploads, {acks} acknowledged, {answers} answered; other frames seen {others}"


def never_reading_flood(client, count):
    client.send(SLCAN_UPLOAD_1000 * count)  # the adapter reads on, whatever we do
    return f"{count} SDO uploads written, nothing read"


def count_flood_answers(good, count):
    """Reads the socketcand client's frames until it has seen `count` answers to uploads of 1000
    (the pty client's flood: the bus carries it, so the adapter has read every request)."""
    seen = 0
    is_answer = sdo_answer_of(NODE, 0x1000)
    deadline = time.monotonic() + 120.0
    while seen < count:
        check(time.monotonic() < deadline, f"{seen} of {count} flood answers on the bus after 120 s")
        unit = good.read_unit(30.0)
        if is_answer(unit):
            check_equal(socketcand_frame(unit)[2], ANSWER_1000, "flood answer on the bus")
            seen += 1
    return seen


def test_slcan_pty_flood(motwin):
    with TempDir() as tmp:
        server, link = serve(motwin, tmp)
        with server:
            memory = Memory(server.proc.pid)
            good = socketcand_client(server.port())
            try:
                try:
                    rounds = run_beside([Worker(windowed_flood, link, WINDOWED_FLOOD_REQUESTS, FLOOD_WINDOW)],
                                        lambda i: sdo_1017_round(good, NODE, i), min_rounds=20, timeout=120.0,
                                        on_round=memory.sample, what="SLCAN pty flood")
                except TestFailure as failure:  # seen once under load: the server closed the socketcand client
                    raise TestFailure(f"{failure}; server alive: {server.alive()}; its stderr ends with "
                                      f"{server.stderr_lines()[-8:]}") from failure
                print(f"  well-behaved socketcand client: {rounds} rounds meanwhile", flush=True)
                memory.check("SLCAN pty flood, client reading")

                # Now a client that never reads: its answers pile up in the pty, then in the adapter
                # up to its bound, and the rest is dropped.
                sleepy = UnitPty(link, SLCAN_UNIT_ENDS)  # the adapter's channel is still open
                try:
                    writer = Worker(never_reading_flood, sleepy, FLOOD_REQUESTS)
                    writer.start()
                    count_flood_answers(good, FLOOD_REQUESTS)  # reading on: socketcand clients must
                    writer.join(30.0)
                    check(not writer.is_alive() and writer.failure is None, f"never-reading writer: {writer.failure}")
                    memory.check("SLCAN pty flood, client not reading")
                    # One line per episode, never one per frame. Two episodes can happen: frames may
                    # already pile up between the windowed client's close and this open (the adapter's
                    # channel stays open), and the flush on open ends that episode.
                    dropped = [line for line in server.stderr_lines() if f"nobody reads {link}" in line]
                    check(1 <= len(dropped) <= 2, f"log lines about dropped output: {len(dropped)} "
                          f"({server.stderr_lines()[-5:]})")
                    sleepy.flush_input()  # what pyserial does on open
                    sleepy.send("V\r")
                    check_equal(first_answer_after_open(sleepy, after_transmits=True, server=server), "V1013\r", "first answer after the flush")
                finally:
                    sleepy.close()
                print(f"  {FLOOD_REQUESTS} more from a client that never read: {dropped[0]}", flush=True)
                sdo_1017_round(good, NODE, 0)
            finally:
                good.close()
            check(server.alive(), "server died")
            server.stop()


if __name__ == "__main__":
    run_tests([test_slcan_pty_garbage_and_slow_clients, test_slcan_pty_flood])
