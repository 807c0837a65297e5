"""Helpers for the storage fault tests (test_fault_storage.py, test_fault_crash_points.py): a full
disk without root, the image file and its leftovers, a clean restart, TMCL program download and
read-back, the records of a TMCM-3216 image, a request answered by a crash instead of a reply.

Builds on motwin_harness (servers, frames, image files) and canopen_harness (raw socketcand).
"""

import os
import signal
import socket
import struct
import sys
import time

from motwin_harness import (
    STATUS_OK, EepromImage, check, check_equal, damaged_lines, expect_reply, frame, parse_reply,
)

STATUS_EEPROM = 5
CALC, DOWNLOAD_START, DOWNLOAD_END, READ_MEMORY = 19, 132, 133, 134
STATUS_NEXT_COMMAND = 101  # an instruction stored in download mode
PROGRAM_LENGTH = 4
ABORT_HARDWARE = 0x06060000
CRASH_VARIABLE = "MOTWIN_CRASH_AT_PERSIST_STEP"


# --- A full disk ----------------------------------------------------------------------------------

def limited_file_size_args(args, limit_bytes):
    """The server command wrapped so that it runs with RLIMIT_FSIZE and SIGXFSZ ignored (both
    survive exec), the way `ulimit -f` in a shell with `trap '' XFSZ` would start it."""
    launcher = ("import os, resource, signal, sys\n"
                "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
                f"resource.setrlimit(resource.RLIMIT_FSIZE, ({limit_bytes}, {limit_bytes}))\n"
                "os.execv(sys.argv[1], sys.argv[1:])\n")
    return [sys.executable, "-c", launcher] + list(args)


def on_full_disk(server, image_bytes):
    """`server`, set to run with every file limited to one byte less than the image: each image
    write fails with EFBIG, as on a full disk."""
    server.args = limited_file_size_args(server.args, len(image_bytes) - 1)
    return server


# --- Image files --------------------------------------------------------------------------------

def read_bytes(path):
    with open(path, "rb") as f:
        return f.read()


def temporary_files(state_dir):
    return sorted(name for name in os.listdir(state_dir) if name.endswith(".tmp"))


def check_clean_restart(server, state_dir, when):
    lines = damaged_lines(server.stderr_lines())
    check(not lines, f"{when}: 'damaged' report after the restart: {lines!r}")
    check_equal(temporary_files(state_dir), [], f"{when}: temporary files after the restart")


CANOPEN_STORAGE_MAGIC = b"MWCO"  # core/canopen/storage.h


def canopen_stored_value(image_bytes, index, sub):
    """The value a TMCM-3216 image records for index/sub (None: not recorded, default at power-up)."""
    image = EepromImage(image_bytes)
    check(image.problem is None, f"TMCM-3216 image: {image.problem}")
    payload = image.payload
    check_equal(payload[:4], CANOPEN_STORAGE_MAGIC, "storage image magic")
    count = struct.unpack_from("<I", payload, 4)[0]
    for i in range(count):
        record_index, record_sub, _, value = struct.unpack_from("<HBBI", payload, 8 + 8 * i)
        if (record_index, record_sub) == (index, sub):
            return value
    return None


# --- TMCL program download ----------------------------------------------------------------------

def program_request(c, command, type_=0, motor=0, value=0):
    return parse_reply(c.request_raw(frame(command, type_, motor, value)))


def send_program(c, k):
    """132 and program k (four CALC ADD k), without the 133 that stores it."""
    expect_reply(program_request(c, DOWNLOAD_START, 0, 0, 0), DOWNLOAD_START, STATUS_OK, what=f"132 of program {k}")
    for _ in range(PROGRAM_LENGTH):
        reply = program_request(c, CALC, 0, 0, k)
        check_equal(reply.status, STATUS_NEXT_COMMAND, f"CALC of program {k} in download mode")


def download_program(c, k):
    """Program k, ended by 133; returns the status of 133."""
    send_program(c, k)
    return program_request(c, DOWNLOAD_END).status


def read_program_values(c):
    """The operands of the four instructions at addresses 0..3 (134)."""
    values = []
    for address in range(PROGRAM_LENGTH):
        reply = program_request(c, READ_MEMORY, 0, 0, address)
        check_equal((reply.status, reply.command), (STATUS_OK, CALC), f"134 at address {address}")
        values.append(reply.value)
    return values


# --- A request answered by a crash ----------------------------------------------------------------

def tcp_bytes_until_closed(client, timeout=30.0):
    """What a TMCL TCP client receives until the server's end closes."""
    received = b""
    deadline = time.monotonic() + timeout
    while True:
        remaining = deadline - time.monotonic()
        check(remaining > 0, f"connection still open after {timeout} s (received {received.hex(' ')})")
        client.sock.settimeout(remaining)
        try:
            chunk = client.sock.recv(4096)
        except socket.timeout:
            continue
        except ConnectionResetError:
            return received
        if not chunk:
            return received
        received += chunk


def check_killed_without_reply(server, received, what):
    """The server ended by SIGKILL (its crash hook) and `received` (what came back to the
    request) is empty."""
    status = server.wait_for_exit()
    check_equal(status, -signal.SIGKILL, f"{what}: exit status (stderr {server.stderr_text()!r})")
    check(not received, f"{what}: a reply arrived before the crash: {received!r}")
