#!/usr/bin/python3
"""The TMCM-1636 firmware image (build-cortex-m/tmcm1636.elf, scripts/build-firmware.sh) booted on
an emulated Cortex-M4F board, qemu-system-arm -M mps2-an386, with its UART0 on a TCP socket:
the host tools talk to it as to a module on a serial line (docs/firmware.md).

- the version string and number (command 136), SAP/GAP, `motwin tmcl` unchanged against it;
- an MVP on the ideal motor reaching its target (GAP 55 polled until set: the board's own time);
- STAP kept over a reset of the emulated board (the monitor's system_reset: the EEPROM region is
  outside the image, so it keeps its contents), the RAM value lost;
- a program downloaded and started with `motwin download`/`start`, and started again by itself
  after a reset (stored in the EEPROM image, GP 77);
- the TMCM-1636 image of firmware 1.13 (tmcm1636_v113.elf, the generation PyTrinamic's TMCM1636
  class targets): its version, its own axis parameters (AP 7 gone, AP 26 and 56 there) and an
  MVP in the units of its position scaler;
- the TMCM-142 image: an MVP, and a GAP as an ASCII line after command 139; an ASCII session of
  several lines in one write (echo, replies in order, status 2 and 4 for bad lines, another
  module's line ignored, LF as a line end, echo switched off by GP 67).

Skipped, visibly (exit status 77), when qemu-system-arm is not installed, or when the ARM
toolchain is not installed and so no image was built. With the toolchain installed a missing
image is a failure: scripts/test.sh builds it.
"""

import os
import shutil
import socket
import subprocess
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from motwin_harness import (  # noqa: E402
    BANK_GLOBAL, BANK_USER, GAP, GET_VERSION, MVP, MVP_ABS, STATUS_OK, STATUS_WRONG_TYPE, VERSION_BINARY, VERSION_STRING,
    Skipped, TcpClient, TempDir, TestFailure, _die_with_parent, check, check_equal, expect_reply, run_tests,
)

SOURCE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FIRMWARE_DIR = os.environ.get("MOTWIN_FIRMWARE_DIR", os.path.join(SOURCE_DIR, "build-cortex-m"))
sys.path.insert(0, os.path.join(SOURCE_DIR, "bench", "firmware"))
from qemu_mps2 import QEMU, monitor_command, qemu_command  # noqa: E402  (shared with bench/firmware_figures.py)
BOOT_TIMEOUT = 60.0
ENTER_ASCII = 139
MOVE_TIMEOUT = 180.0  # 20000 counts at the default ramp take about 1 s of the board's time


def firmware_image(name):
    if shutil.which(QEMU) is None:
        raise Skipped(f"{QEMU} not installed (Debian: qemu-system-arm; scripts/install-deps.sh)")
    image = os.path.join(FIRMWARE_DIR, f"{name}.elf")
    if not os.path.exists(image):
        if shutil.which("arm-none-eabi-g++") is None:
            raise Skipped("arm-none-eabi-g++ not installed, so no firmware image was built "
                          "(Debian: gcc-arm-none-eabi; scripts/install-deps.sh)")
        raise TestFailure(f"{image} is missing: run scripts/build-firmware.sh")
    return image


def free_port():
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class EmulatedBoard:
    """qemu running one firmware image: UART0 on a TCP server socket, the monitor on a Unix socket."""

    def __init__(self, image, state_dir):
        self.monitor_path = os.path.join(state_dir, "monitor.sock")
        self.log_path = os.path.join(state_dir, "qemu.log")
        for _attempt in range(5):  # another process may take the port between probe and bind
            self.port = free_port()
            with open(self.log_path, "wb") as log:
                self.process = subprocess.Popen(
                    qemu_command(image, self.monitor_path, f"tcp:127.0.0.1:{self.port},server=on,wait=off"),
                    stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT, preexec_fn=_die_with_parent)
            deadline = time.monotonic() + BOOT_TIMEOUT
            while time.monotonic() < deadline and self.process.poll() is None:
                try:
                    self.client = TcpClient(self.port)
                    return
                except OSError:
                    time.sleep(0.02)
            self.stop()
        with open(self.log_path, encoding="utf-8", errors="replace") as log:
            raise TestFailure(f"qemu did not open its serial port: {log.read()}")

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()

    def stop(self):
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait()

    def monitor(self, command):
        return monitor_command(self.monitor_path, command)


def wait_until_answering(client):
    """After a reset: the firmware answers once it has started again (a frame sent while it
    starts may be lost, so each try is a fresh frame after a pause longer than the resync gap)."""
    deadline = time.monotonic() + BOOT_TIMEOUT
    while True:
        try:
            return client.request(GET_VERSION, 1, timeout=1.0)
        except TestFailure:
            if time.monotonic() > deadline:
                raise
            client.read_available(0.05)


def test_version_and_parameters(motwin):
    image = firmware_image("tmcm1636")
    with TempDir() as state, EmulatedBoard(image, state) as board:
        client = board.client
        check_equal(client.version_string(), VERSION_STRING, "command 136 type 0")
        expect_reply(client.request(GET_VERSION, 1), GET_VERSION, value=VERSION_BINARY, what="command 136 type 1")
        check_equal(client.gap(43), 4000, "GAP 43 (max velocity) factory default")
        client.sap(43, 3210)
        check_equal(client.gap(43), 3210, "GAP 43 after SAP")
        expect_reply(client.request(GAP, 250), GAP, STATUS_WRONG_TYPE, what="GAP 250 (no such parameter)")
        # A frame for another address is not answered; a bad checksum is status 1.
        client.send_raw(bytes([5, GAP, 43, 0, 0, 0, 0, 0, (5 + GAP + 43) & 0xFF]))
        client.expect_no_reply(timeout=0.5, what="GAP to address 5")
        bad = bytes([1, GAP, 43, 0, 0, 0, 0, 0, 0])
        check_equal(client.request_raw(bad)[2], 1, "status of a frame with a wrong checksum")
        # The host tool, unchanged: one connection per instruction.
        client.sock.close()
        result = subprocess.run([motwin, "tmcl", "--tcp", f"127.0.0.1:{board.port}", "GAP", "43", "0"],
                                capture_output=True, text=True, timeout=60)
        check(result.returncode == 0 and "status 100" in result.stdout and "value 3210" in result.stdout,
              f"motwin tmcl GAP 43: {result.returncode} {result.stdout!r} {result.stderr!r}")


def test_mvp_reaches_target(motwin):
    image = firmware_image("tmcm1636")
    with TempDir() as state, EmulatedBoard(image, state) as board:
        client = board.client
        start_ms = client.ggp(132, BANK_GLOBAL)
        expect_reply(client.request(MVP, MVP_ABS, 0, 20000), MVP, STATUS_OK, what="MVP ABS 20000")
        client.wait_for("GAP 55 (position reached)", lambda: client.gap(55) == 1, MOVE_TIMEOUT, interval=0.05)
        position = client.gap(52)
        check(abs(position - 20000) <= 5, f"GAP 52 (actual position) {position}, not within 5 of 20000")
        check_equal(client.gap(50), 20000, "GAP 50 (target position)")
        elapsed_ms = client.ggp(132, BANK_GLOBAL) - start_ms
        # 20000 counts at 4000 rpm and 2000 rpm/s: the board's tick timer saw the move's duration.
        check(elapsed_ms >= 500, f"GP 132 advanced only {elapsed_ms} ms during the move")


def test_stap_survives_a_board_reset(motwin):
    image = firmware_image("tmcm1636")
    with TempDir() as state, EmulatedBoard(image, state) as board:
        client = board.client
        client.sap(43, 1234)
        client.stap(43)
        client.sap(44, 999)  # not stored: back to the factory default after the reset
        board.monitor("system_reset")
        wait_until_answering(client)
        check_equal(client.gap(43), 1234, "GAP 43 after the reset (stored with STAP)")
        check_equal(client.gap(44), 2000, "GAP 44 after the reset (not stored)")
        # A second reset reads the other bank of the EEPROM region: still the same image.
        client.sap(43, 2345)
        client.stap(43)
        board.monitor("system_reset")
        wait_until_answering(client)
        check_equal(client.gap(43), 2345, "GAP 43 after a second STAP and reset")


def test_stored_program_runs_and_autostarts_after_a_reset(motwin):
    """`motwin download` and `motwin start` unchanged; the program is in the EEPROM image, so after
    a board reset it starts by itself (GP 77 = 1, the factory default) and runs again."""
    image = firmware_image("tmcm1636")
    program = os.path.join(SOURCE_DIR, "tests", "programs", "manual_6_4_variables.tmc")  # user variable 42 ends at 2468
    with TempDir() as state, EmulatedBoard(image, state) as board:
        client = board.client
        client.sock.close()  # one client at a time on qemu's socket
        endpoint = f"127.0.0.1:{board.port}"
        for args in (["download", program], ["start"]):
            result = subprocess.run([motwin, *args, "--tcp", endpoint], capture_output=True, text=True, timeout=120)
            check(result.returncode == 0, f"motwin {args[0]}: {result.returncode} {result.stdout!r} {result.stderr!r}")
        client = board.client = TcpClient(board.port)
        client.wait_for("user variable 42 = 2468", lambda: client.ggp(42, BANK_USER) == 2468, MOVE_TIMEOUT)
        client.sgp(42, BANK_USER, 0)
        board.monitor("system_reset")
        wait_until_answering(client)
        client.wait_for("user variable 42 = 2468 after the reset", lambda: client.ggp(42, BANK_USER) == 2468,
                        MOVE_TIMEOUT)


def test_tmcm1636_v113_image(motwin):
    image = firmware_image("tmcm1636_v113")
    with TempDir() as state, EmulatedBoard(image, state) as board:
        client = board.client
        check_equal(client.version_string(), b"1636V113", "command 136 type 0")
        expect_reply(client.request(GET_VERSION, 1), GET_VERSION, value=0x0664010D, what="command 136 type 1 (1636, 1, 13)")
        expect_reply(client.request(GAP, 7), GAP, STATUS_WRONG_TYPE, what="GAP 7 (dual shunt factor, gone in 1.13)")
        check_equal(client.gap(26), 0, "GAP 26 (velocity sensor selection, new in 1.13)")
        check_equal(client.gap(56), 65536, "GAP 56 (position scaler, new in 1.13) factory default")
        client.sap(56, 1000)
        expect_reply(client.request(MVP, MVP_ABS, 0, 250), MVP, STATUS_OK, what="MVP ABS 250")
        client.wait_for("GAP 55 (position reached)", lambda: client.gap(55) == 1, MOVE_TIMEOUT, interval=0.05)
        check_equal(client.gap(50), 250, "GAP 50 (target position, in position scaler units)")
        # AP 55 rises inside the target window (AP 53, 54) while the ramp's last counts are still
        # to come; a poll that lands there (a busy host slows qemu) reads 248: wait for the end.
        client.wait_for("GAP 52 (actual position) within 1 of 250", lambda: abs(client.gap(52) - 250) <= 1,
                        MOVE_TIMEOUT, interval=0.05)


def test_tmcm142_moves_and_speaks_ascii(motwin):
    image = firmware_image("tmcm142")
    with TempDir() as state, EmulatedBoard(image, state) as board:
        client = board.client
        check_equal(client.version_string(), b"142V1.06", "TMCM-142 command 136 type 0")
        expect_reply(client.request(MVP, MVP_ABS, 0, 5000), MVP, STATUS_OK, what="MVP ABS 5000")
        client.wait_for("GAP 8 (position reached)", lambda: client.gap(8) == 1, MOVE_TIMEOUT, interval=0.05)
        check_equal(client.gap(1), 5000, "GAP 1 (actual position, microsteps)")
        # Command 139: the binary reply, then ASCII lines (docs/ascii-mode.md); BIN goes back.
        expect_reply(client.request(ENTER_ASCII, 0), ENTER_ASCII, STATUS_OK, what="command 139")
        client.send_raw(b"AGAP 1, 0\r")
        text = b""
        deadline = time.monotonic() + 30.0
        while b"BA 100 5000\r" not in text and time.monotonic() < deadline:
            text += client.read_available(0.5)
        check(b"BA 100 5000\r" in text, f"ASCII GAP 1: {text!r}")
        client.send_raw(b"ABIN\r")
        after_bin = b""  # the echo of the line, then its reply "BA 100 ...\r"
        while not (b"BA 100 " in after_bin and after_bin.endswith(b"\r")):
            more = client.read_available(5.0)
            check(more != b"", f"no reply to BIN: {after_bin!r}")
            after_bin += more
        check_equal(client.gap(1), 5000, "binary GAP 1 after BIN")


def read_exactly(client, expected, what):
    received = b""
    while len(received) < len(expected):
        more = client.read_available(5.0)
        check(more != b"", f"{what}: got only {received!r} of {expected!r}")
        received += more
    check_equal(received, expected, what)


def test_tmcm142_ascii_session(motwin):
    """Lines are read and answered one at a time (docs/ascii-mode.md), even when they arrive in
    one write: each echo follows the previous line's reply."""
    image = firmware_image("tmcm142")
    with TempDir() as state, EmulatedBoard(image, state) as board:
        client = board.client
        expect_reply(client.request(ENTER_ASCII, 0), ENTER_ASCII, STATUS_OK, what="command 139")
        lines = [b"ASAP 4, 0, 1234\r", b"AGAP 4, 0\r", b"AFOO 1\r", b"AGAP 4,,0\r", b"BGAP 4, 0\r",
                 b"a gap 4 0\n"]
        client.send_raw(b"".join(lines))
        read_exactly(client, b"ASAP 4, 0, 1234\rBA 100 1234\r" b"AGAP 4, 0\rBA 100 1234\r"
                     b"AFOO 1\rBA 2 0\r" b"AGAP 4,,0\rBA 4 0\r" b"a gap 4 0\nBA 100 1234\r",
                     "echo and reply of each line in turn (the line for module B neither echoed nor answered)")
        # GP 67 bit 5: no echo from the next character on (the line that sets it is echoed).
        client.send_raw(b"ASGP 67, 0, 32\rAGAP 4, 0\r")
        read_exactly(client, b"ASGP 67, 0, 32\rBA 100 32\rBA 100 1234\r", "echo off after SGP 67, 0, 32")


if __name__ == "__main__":
    run_tests([test_version_and_parameters, test_mvp_reaches_target, test_stap_survives_a_board_reset,
               test_stored_program_runs_and_autostarts_after_a_reset, test_tmcm1636_v113_image,
               test_tmcm142_moves_and_speaks_ascii, test_tmcm142_ascii_session])
