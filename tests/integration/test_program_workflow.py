#!/usr/bin/python3
"""The TMCL program workflow from the command line: `motwin download` (assemble, download,
verify with 134) against `motwin serve` over TCP and over its pseudo-terminal (`--serial`),
`motwin start|stop|step|status`, a downloaded program that survives a restart of `motwin serve`
on the same state directory and autostarts (GP 77), a read-back mismatch against a fake module,
and `motwin run` writing a CSV trace whose values are checked.
"""

import csv
import os
import socket
import struct
import subprocess
import sys
import threading
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from motwin_harness import (  # noqa: E402
    BANK_GLOBAL, BANK_USER, DEFAULT_AUTO_START, GAP, Server, TempDir, check, check_equal, checksum, expect_reply,
    run_tests,
)

PROGRAMS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "programs")
JUMP_TABLE = os.path.join(PROGRAMS, "manual_6_6_jump_table.tmc")
VARIABLES = os.path.join(PROGRAMS, "manual_6_4_variables.tmc")
READ_MEMORY, APP_STATUS = 134, 135
CLI_TIMEOUT = 60


def motwin_cli(motwin, *args, expect=0):
    result = subprocess.run([motwin, *args], stdin=subprocess.DEVNULL, capture_output=True, text=True,
                            timeout=CLI_TIMEOUT)
    check(result.returncode == expect,
          f"motwin {' '.join(args)}: exit status {result.returncode}, expected {expect}\n"
          f"stdout: {result.stdout}\nstderr: {result.stderr}")
    return result


def status_fields(motwin, port):
    """`motwin status` as a dict: 'application status' -> 'run (1)' ..."""
    out = motwin_cli(motwin, "status", "--tcp", f"127.0.0.1:{port}").stdout
    fields = {}
    for line in out.splitlines():
        key, _, value = line.partition(":")
        fields[key.strip()] = value.strip()
    return fields


def wait_for_status(motwin, port, key, expected, timeout=20.0):
    """Polls `motwin status` until `key` shows `expected` (a value, or a predicate of it)."""
    deadline = time.monotonic() + timeout
    while True:
        fields = status_fields(motwin, port)
        if expected(fields.get(key)) if callable(expected) else fields.get(key) == expected:
            return fields
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {key} = {expected!r}; last status {fields!r}")
        time.sleep(0.02)


def test_download_start_status(motwin):
    """Download the manual's jump table (6.6), check it with 134, call Func3 by its label and
    follow it with `motwin status` until its STOP. In real time: the WAIT of Func3 (7 s) is the
    window in which `motwin status` (a process of its own, slow to start on a loaded machine) and
    the ramp check must see it."""
    with TempDir() as tmp:
        with Server(motwin, os.path.join(tmp, "state")) as server:
            endpoint = f"127.0.0.1:{server.tcp_port}"
            out = motwin_cli(motwin, "download", JUMP_TABLE, "--tcp", endpoint).stdout
            check("17 instructions downloaded to addresses 0..16" in out and "verified" in out, f"download said {out!r}")
            with server.tcp() as client:
                # Address 0 is "Func1: JA Func1Start" with Func1Start = 3; 134 type 0 answers with
                # the stored opcode as command byte, type 1 with type << 8 | motor.
                reply = client.request(READ_MEMORY, 0, 0, 0)
                check_equal((reply.status, reply.command, reply.value), (100, 22, 3), "134 type 0 at address 0")
                reply = client.request(READ_MEMORY, 1, 0, 8)
                check_equal((reply.status, reply.command, reply.value), (100, 2, 0), "134 type 1 at 8 (ROL 0, 500)")

                fields = status_fields(motwin, server.tcp_port)
                check_equal(fields["application status"], "stop (0)", "before start")
                check_equal(fields["download pointer"], "18", "after 17 instructions and the trailing NOP")

                out = motwin_cli(motwin, "start", "--tcp", endpoint, "--label", "Func3", "--program", JUMP_TABLE).stdout
                check_equal(out.strip(), "program started at Func3 (address 2)", "start output")
                # Func3Start (12): ROR 0, 1000; WAIT TICKS, 0, 700; MST 0; STOP (15).
                fields = wait_for_status(motwin, server.tcp_port, "waiting", "yes (WAIT in progress)")
                check_equal(fields["application status"], "run (1)", "while in WAIT TICKS")
                check_equal(fields["program counter"], "14", "after the WAIT at 13")
                client.wait_for("AP 42 = 1000 rpm during Func3 (after its 0.5 s ramp)",
                                lambda: expect_reply(client.request(GAP, 42), GAP).value == 1000, timeout=10)
                check_equal(status_fields(motwin, server.tcp_port)["application status"], "run (1)", "still in WAIT")
                fields = wait_for_status(motwin, server.tcp_port, "application status", "stop (0)")
                check_equal(fields["stop reason"], "STOP instruction (1) at address 15", "stop reason")
                check_equal(fields["waiting"], "no", "after STOP")
            server.stop()


def test_stop_step_and_registers(motwin):
    """A counting loop: start, stop (stop reason: the host), step one instruction at a time and
    watch the accumulator in `motwin status`."""
    with TempDir() as tmp:
        source = os.path.join(tmp, "count.tmc")
        with open(source, "w") as f:
            f.write("Loop: CALC ADD, 1\n      CALCX LOAD\n      JA Loop\n")
        with Server(motwin, os.path.join(tmp, "state")) as server:
            endpoint = f"127.0.0.1:{server.tcp_port}"
            motwin_cli(motwin, "download", source, "--tcp", endpoint)
            motwin_cli(motwin, "start", "--tcp", endpoint)
            wait_for_status(motwin, server.tcp_port, "accumulator", lambda value: int(value) > 10)
            check_equal(motwin_cli(motwin, "stop", "--tcp", endpoint).stdout.strip(), "program stopped", "stop")
            fields = status_fields(motwin, server.tcp_port)
            check_equal(fields["application status"], "stop (0)", "after stop")
            check(fields["stop reason"].startswith("stopped by the host (2) at address "), f"{fields!r}")
            accumulator = int(fields["accumulator"])
            check(accumulator > 10, f"the loop counted: {fields!r}")
            time.sleep(0.05)
            check_equal(int(status_fields(motwin, server.tcp_port)["accumulator"]), accumulator, "nothing runs")
            # Step until the next CALC ADD ran: the accumulator grows by exactly one.
            for _ in range(3):
                motwin_cli(motwin, "step", "--tcp", endpoint)
                time.sleep(0.01)
            fields = status_fields(motwin, server.tcp_port)
            check_equal(int(fields["accumulator"]), accumulator + 1, "three steps run one CALC ADD")
            check_equal(fields["application status"], "step (2)", "mode after stepping")
            check(int(fields["X register"]) in (accumulator, accumulator + 1), f"CALCX LOAD copies A to X: {fields!r}")
            motwin_cli(motwin, "start", "--tcp", endpoint, "--continue")
            check_equal(status_fields(motwin, server.tcp_port)["application status"], "run (1)", "continued")
            server.stop()


# Sets user variable 100 (not stored, so only the program can make it 42) and counts in 101.
# The assembler appends a STOP: 5 instructions.
COUNTER_PROGRAM = "SGP 100, 2, 42\nLoop: CALC ADD, 1\n      AGP 101, 2\n      JA Loop\n"


def write_counter_program(tmp):
    source = os.path.join(tmp, "counter.tmc")
    with open(source, "w") as f:
        f.write(COUNTER_PROGRAM)
    return source


def check_counter_program_runs(client, what):
    client.wait_for(f"{what}: user variable 100 = 42", lambda: client.ggp(100, BANK_USER) == 42, timeout=10)
    check_equal(client.ggp(128, BANK_GLOBAL), 1, f"{what}: GP 128 application status run")
    first = client.ggp(101, BANK_USER)
    client.wait_for(f"{what}: the loop counts", lambda: client.ggp(101, BANK_USER) != first, timeout=5)


def test_downloaded_program_survives_a_restart_and_autostarts(motwin):
    """Download (not started), restart `motwin serve` on the same state directory: the program is
    in program memory (134) and GP 77 = 1 started it at power-up. With GP 77 = 0 it stays stopped."""
    with TempDir() as tmp:
        source = write_counter_program(tmp)
        state = os.path.join(tmp, "state")
        with Server(motwin, state) as server:
            out = motwin_cli(motwin, "download", source, "--tcp", f"127.0.0.1:{server.tcp_port}").stdout
            check("5 instructions downloaded to addresses 0..4" in out and "verified" in out, f"download said {out!r}")
            with server.tcp() as client:
                check_equal(client.ggp(77, BANK_GLOBAL), DEFAULT_AUTO_START, "GP 77 factory default: autostart")
                check_equal(client.ggp(128, BANK_GLOBAL), 0, "a download does not start the program")
                check_equal(client.ggp(100, BANK_USER), 0, "nothing ran before the restart")
            server.stop()
        with Server(motwin, state) as server:
            with server.tcp() as client:
                check_counter_program_runs(client, "after the restart")
                # The program itself came back from the image: SGP 100, 2, 42 at address 0, JA 1 at 3.
                reply = client.request(READ_MEMORY, 0, 0, 0)
                check_equal((reply.status, reply.command, reply.value), (100, 9, 42), "134 type 0 at address 0")
                reply = client.request(READ_MEMORY, 1, 0, 0)
                check_equal((reply.status, reply.command, reply.value), (100, 9, (100 << 8) | 2), "134 type 1 at 0")
                reply = client.request(READ_MEMORY, 0, 0, 3)
                check_equal((reply.status, reply.command, reply.value), (100, 22, 1), "134 type 0 at address 3")
            check_equal(status_fields(motwin, server.tcp_port)["application status"], "run (1)", "motwin status")
            with server.tcp() as client:
                client.sgp(77, BANK_GLOBAL, 0)  # automatically stored
            server.stop()
        with Server(motwin, state) as server:
            with server.tcp() as client:
                time.sleep(0.3)
                check_equal(client.ggp(128, BANK_GLOBAL), 0, "GP 77 = 0: no autostart")
                check_equal(client.ggp(100, BANK_USER), 0, "the program did not run")
                check_equal(client.request(READ_MEMORY, 0, 0, 0).value, 42, "but it is still stored")
            server.stop()


def test_download_and_start_over_the_serial_pty(motwin):
    """`motwin download --serial` and `motwin start --serial` on the server's pseudo-terminal,
    then a pyserial client on the same link sees the program run."""
    with TempDir() as tmp:
        source = write_counter_program(tmp)
        link = os.path.join(tmp, "tmcm1636")
        with Server(motwin, os.path.join(tmp, "state"), tcp=False, pty_link=link) as server:
            out = motwin_cli(motwin, "download", source, "--serial", link).stdout
            check("5 instructions downloaded to addresses 0..4" in out and "verified" in out, f"download said {out!r}")
            with server.serial() as client:
                check_equal(client.ggp(128, BANK_GLOBAL), 0, "downloaded, not started")
                reply = client.request(READ_MEMORY, 0, 0, 2)
                check_equal((reply.status, reply.command, reply.value), (100, 35, 0), "134 at 2: AGP 101, 2")
            out = motwin_cli(motwin, "start", "--serial", link).stdout
            check("program started" in out, f"start said {out!r}")
            with server.serial() as client:
                check_counter_program_runs(client, "started over the pty")
            server.stop()


class FakeModule(threading.Thread):
    """A TMCL module over TCP that accepts a download but reads back a different value at one
    address, so that `motwin download` must report the mismatch."""

    def __init__(self, bad_address):
        super().__init__(daemon=True)
        self.listener = socket.socket()
        self.listener.bind(("127.0.0.1", 0))
        self.listener.listen(1)
        self.port = self.listener.getsockname()[1]
        self.bad_address = bad_address
        self.memory = {}

    def run(self):
        connection, _ = self.listener.accept()
        pointer, downloading = 0, False
        with connection:
            while True:
                data = b""
                while len(data) < 9:
                    chunk = connection.recv(9 - len(data))
                    if not chunk:
                        return
                    data += chunk
                _, command, type_, motor, value = struct.unpack(">BBBBi", data[:8])
                status, reply_command, reply_value = 100, command, value
                if command == 132:
                    pointer, downloading = value, True
                elif command == 133:
                    downloading = False
                elif downloading:
                    self.memory[pointer] = (command, type_, motor, value)
                    pointer += 1
                    status = 101
                elif command == READ_MEMORY:
                    stored = self.memory.get(value, (0, 0, 0, 0))
                    reply_command = stored[0]
                    reply_value = stored[3] + (1 if value == self.bad_address else 0) if type_ == 0 else \
                        (stored[1] << 8) | stored[2]
                body = struct.pack(">BBBBi", 2, 1, status, reply_command, reply_value)
                connection.sendall(body + bytes([checksum(body)]))


def test_download_reports_a_read_back_mismatch(motwin):
    fake = FakeModule(bad_address=3)
    fake.start()
    result = motwin_cli(motwin, "download", JUMP_TABLE, "--tcp", f"127.0.0.1:{fake.port}", expect=1)
    check("address 3: sent MVP ABS, 0, 1000 (4 0 0 1000), the module holds MVP ABS, 0, 1001 (4 0 0 1001)"
          in result.stderr, f"stderr: {result.stderr!r}")
    check("verification failed: 1 of 17 instructions" in result.stderr, f"stderr: {result.stderr!r}")
    check("verified" not in result.stdout, f"stdout: {result.stdout!r}")


def test_download_of_a_bad_program_sends_nothing(motwin):
    with TempDir() as tmp:
        source = os.path.join(tmp, "bad.tmc")
        with open(source, "w") as f:
            f.write("MVP ABS, 0, 100\nJA Nowhere\n")
        # No server: the assembler fails before any connection is tried.
        result = motwin_cli(motwin, "download", source, "--tcp", "127.0.0.1:9", expect=1)
        check(f"{source}:2:4: error:" in result.stderr and "Nowhere" in result.stderr, f"stderr: {result.stderr!r}")


def read_trace(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], [[float(v) if i == 0 else int(v) for i, v in enumerate(row)] for row in rows[1:]]


def test_run_writes_a_trace(motwin):
    """`motwin run` on a move to 20000: the position column rises monotonically to the MVP
    target and stays there; the program stops at its STOP; sampling goes on until --for."""
    with TempDir() as tmp:
        source = os.path.join(tmp, "move.tmc")
        with open(source, "w") as f:
            f.write("MVP ABS, 0, 20000\nWAIT POS, 0, 0\nSGP 0, 2, 7\nSTOP\n")
        trace = os.path.join(tmp, "trace.csv")
        out = motwin_cli(motwin, "run", source, "--module", "tmcm-1636", "--for", "2s", "--trace", trace,
                         "--sample", "10ms", "--param", "52,42", "--var", "0").stdout
        check("program: stopped by t=" in out and "STOP instruction at address 3" in out, f"run said {out!r}")
        header, rows = read_trace(trace)
        check_equal(header, ["time_s", "AP52", "AP42", "var0"], "trace header")
        check_equal(len(rows), 201, "samples at 0, 10 ms ... 2 s")
        for i, row in enumerate(rows):
            check(abs(row[0] - i * 0.01) < 1e-9, f"row {i}: time {row[0]}")
        positions = [row[1] for row in rows]
        check(all(b >= a for a, b in zip(positions, positions[1:])), "the position only rises")
        check_equal(positions[0], 0, "position at t = 0")
        check_equal(positions[-1], 20000, "position at the end: the MVP target")
        check(0 < max(row[2] for row in rows) <= 4000, "velocity within the default max velocity (AP 43)")
        check_equal(rows[-1][2], 0, "at rest at the end")
        reached = next(row for row in rows if row[3] == 7)
        check(abs(reached[1] - 20000) <= 5, f"SGP after WAIT POS ran within AP 53 of the target: {reached}")


def test_run_until_stopped_with_a_label_and_stdout(motwin):
    result = motwin_cli(motwin, "run", JUMP_TABLE, "--label", "Func2", "--for", "10s", "--until-stopped",
                        "--sample", "100ms", "--param", "40", "--trace", "-")
    lines = result.stdout.splitlines()
    check_equal(lines[0], "time_s,AP40", "header on stdout")
    values = [int(line.split(",")[1]) for line in lines[1:]]
    check(values[1] == -500, f"ROL 0, 500 right after the start: {values}")
    check(values[-1] == 0, f"MST at the end: {values}")
    check(len(values) < 20, f"--until-stopped ended the run about 1 s in: {len(values)} samples")
    check("STOP instruction at address 11" in result.stderr, f"report on stderr: {result.stderr!r}")


def test_run_variables_and_a_faulting_program(motwin):
    result = motwin_cli(motwin, "run", VARIABLES, "--for", "10ms", "--var", "42", "--param", "52", "--trace", "-")
    check_equal(result.stdout.splitlines()[-1].split(","), ["0.010000", "0", "2468"], "6.4: variable 42 doubled")
    with TempDir() as tmp:
        source = os.path.join(tmp, "wild.tmc")
        with open(source, "w") as f:
            f.write("CALC LOAD, 1\nJA 4000\n")
        result = motwin_cli(motwin, "run", source, "--for", "100ms", "--trace", os.path.join(tmp, "t.csv"), expect=1)
        check("jump, call or return outside program memory at address 1" in result.stdout, f"{result.stdout!r}")


if __name__ == "__main__":
    run_tests([test_download_start_status, test_stop_step_and_registers,
               test_downloaded_program_survives_a_restart_and_autostarts, test_download_and_start_over_the_serial_pty,
               test_download_reports_a_read_back_mismatch,
               test_download_of_a_bad_program_sends_nothing, test_run_writes_a_trace,
               test_run_until_stopped_with_a_label_and_stdout, test_run_variables_and_a_faulting_program])
