#!/usr/bin/python3
"""Writes the seed corpora in fuzz/corpus/<target>/ from the inputs the tests use.

Run from anywhere: `fuzz/make_seeds.py [--motwin build/motwin]`. With --motwin, the EEPROM seeds
start from the factory image a real `motwin serve` writes; without it they are kept as they are.
The seeds are committed; libFuzzer adds what it finds to a copy (scripts/fuzz.sh).
"""

import argparse
import base64
import os
import random
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
CORPUS = os.path.join(HERE, "corpus")


CLEARED = set()


def write(target, name, data):
    directory = os.path.join(CORPUS, target)
    if target not in CLEARED:  # seeds of an older input format go
        shutil.rmtree(directory, ignore_errors=True)
        CLEARED.add(target)
    os.makedirs(directory, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(directory, name), "wb") as f:
        f.write(data)


class Fdp:
    """Bytes that libFuzzer's FuzzedDataProvider reads back as the values given, in order.

    FuzzedDataProvider.h takes integers from the end of the input, the most significant byte first,
    as many bytes as the range needs (none for a range of one value), modulo the range: so each
    value is written little-endian, and the values in reverse order. ConsumeBool is one byte's bit 0.
    The seeds of a target written this way follow the order its .cpp consumes values in: rerun
    this script when that order changes.
    """

    def __init__(self):
        self.chunks = []

    def int(self, value, lo, hi):
        assert lo <= value <= hi, (value, lo, hi)
        span = hi - lo
        length = 0
        while length < 8 and span >> (8 * length) > 0:
            length += 1
        self.chunks.append((value - lo).to_bytes(length, "little"))
        return self

    def bool(self, value):
        return self.int(1 if value else 0, 0, 255)

    def u8(self, value):
        return self.int(value, 0, 255)

    def u32(self, value):
        return self.int(value & 0xFFFFFFFF, 0, 0xFFFFFFFF)

    def i32(self, value):
        return self.int(value, -2**31, 2**31 - 1)

    def eight(self, data):
        """A frame's 8 data bytes, each a ConsumeIntegral<uint8_t>: `data`, then zeros."""
        for b in (list(data) + [0] * 8)[:8]:
            self.u8(b)
        return self

    def length_and_eight(self, data, length=8):
        """`int(0..15) == 0 ? int(0..8) : 8` for the length, then the 8 bytes (the CANopen targets)."""
        if length == 8:
            self.int(1, 0, 15)
        else:
            self.int(0, 0, 15).int(length, 0, 8)
        return self.eight(data)

    def data(self):
        return b"".join(reversed(self.chunks))


def tmcl_frame(command, type_=0, motor=0, value=0, address=1):
    body = struct.pack(">BBBBI", address, command, type_, motor, value & 0xFFFFFFFF)
    return body + bytes([sum(body) & 0xFF])


def tmcl_seeds():
    # Byte 0: pause before every n-th byte (0: never). Frames as the integration tests send them.
    stream = [
        ("gap_sap_stap", [tmcl_frame(6, 43), tmcl_frame(5, 43, 0, 3100), tmcl_frame(7, 43), tmcl_frame(8, 43)]),
        ("globals", [tmcl_frame(9, 0, 2, -1), tmcl_frame(10, 0, 2), tmcl_frame(11, 0, 2), tmcl_frame(10, 66, 0)]),
        ("version_reset", [tmcl_frame(136, 0), tmcl_frame(136, 1), tmcl_frame(255, 0, 0, 1234), tmcl_frame(6, 43)]),
        ("factory", [tmcl_frame(137, 0, 0, 1234), tmcl_frame(137, 0, 0, 1)]),
        ("motion", [tmcl_frame(1, 0, 0, 500), tmcl_frame(3), tmcl_frame(4, 0, 0, 10000), tmcl_frame(138, 0, 0, 1)]),
        ("download", [tmcl_frame(132), tmcl_frame(5, 4, 0, 1000), tmcl_frame(28), tmcl_frame(133),
                      tmcl_frame(134, 0, 0, 0), tmcl_frame(129, 1), tmcl_frame(135, 0), tmcl_frame(128)]),
        ("address_change", [tmcl_frame(9, 66, 0, 5), tmcl_frame(6, 43, address=5), tmcl_frame(6, 43)]),
        ("ascii_switch", [tmcl_frame(139), b"AGAP 43, 0\r", b"ABIN\r", tmcl_frame(6, 43)]),
    ]
    for name, frames in stream:
        write("tmcl_serial_stream", name, b"\0" + b"".join(frames))
    bad = bytearray(tmcl_frame(6, 44))
    bad[8] ^= 0x5A
    write("tmcl_serial_stream", "bad_checksum_then_pause", b"\x09" + bytes(bad) + tmcl_frame(6, 43)[:4] + tmcl_frame(6, 43))
    write("tmcl_serial_stream", "foreign_address", b"\0" + tmcl_frame(5, 43, 0, 1, address=9) + b"\x01\x05")

    echo_modes = {"each": 0x00, "line": 0x10, "none": 0x20}
    lines = ("AMVP ABS, 0, 50000\r", "A GAP 52, 0\r", "ASAP 4, 0, 1000\rAGAP 4, 0\r", "ARUN\rASTOP\r",
             "ABIN\r", "BGAP 4, 0\r", "AGAX 4\x08P 4, 0\r", "A" + "X" * 90 + "\r", "ASGP 67, 0, 17\rAGGP 67, 0\n",
             "ACALC ADD, 5\rAGAP 1, 0\r", "ASTAP 4, 0\r")
    for i, line in enumerate(lines):
        mode = list(echo_modes.values())[i % 3]
        write("tmcl_ascii", f"line_{i:02d}", bytes([mode]) + line.encode("latin-1"))
    # Byte 0 bit 0: the TMCM-142, the module whose manual has the interface (its 6.6 examples).
    tmcm142_lines = ("AMVP ABS, 0, 50000\r", "A MVP ABS, 0, 50000\r", "AROL 0, 500\rA MST 0\r", "ABIN\rAGAP 1, 0\r",
                     "aGAP 1, 0\n\rAGGP 67, 0\r", "ASGP 66, 0, 2\rBGAP 1, 0\rASGP 66, 0, 27\r", "ARUN 5\rASTOP\r",
                     "A\x01GAP 1, 0\rA\rA   \r", "AGAP 1,, 0\rAGAP 1, 0, 0, 0\rAFOO\rA136 0\r",
                     "ASGP 67, 0, 16\rAGAP 1, 0\rASGP 67, 0, 0\rA\x08\x08BGAP 1, 0\r")
    for i, line in enumerate(tmcm142_lines):
        mode = list(echo_modes.values())[i % 3] | 1
        write("tmcl_ascii", f"tmcm142_{i:02d}", bytes([mode]) + line.encode("latin-1"))


def program_seeds():
    programs = os.path.join(ROOT, "tests", "programs")
    for name in sorted(os.listdir(programs)):
        path = os.path.join(programs, name)
        with open(path, "rb") as f:
            data = f.read()
        if name.endswith(".tmc") and len(data) < 8192:
            write("tmcl_assembler", "src_" + os.path.splitext(name)[0], b"\0" + data)
        elif name.endswith(".bin") and len(data) < 8192:
            write("tmcl_assembler", "bin_" + os.path.splitext(name)[0], b"\1" + data)
    # A .bin made of records: SAP, MVP, WAIT, JA back, STOP.
    records = b""
    for command, type_, motor, value in ((5, 4, 0, 1000), (4, 0, 0, 2000), (27, 1, 0, 0), (22, 0, 0, 0), (28, 0, 0, 0)):
        body = struct.pack(">BBBi", command, type_, motor, value)
        records += body + bytes([sum(body) & 0xFF])
    write("tmcl_assembler", "bin_loop", b"\1" + records)


def manual_example_frames():
    """The binary-form examples of the TMCM-1636 manual, as tests/unit/core_tmcl_manual_examples_test.cpp
    sends them: (name, 9-byte frame)."""
    path = os.path.join(ROOT, "tests", "unit", "core_tmcl_manual_examples_test.cpp")
    with open(path) as f:
        text = f.read()
    examples = []
    for name, body in re.findall(r'\{"([^"]+)", \{((?:0x[0-9A-Fa-f]{2}, ){8}0x[0-9A-Fa-f]{2})\}, \d+\}', text):
        examples.append((name, bytes(int(b, 16) for b in body.split(", "))))
    if len(examples) < 20:
        sys.exit(f"make_seeds: only {len(examples)} manual examples found in {path}")
    return examples


def tmcl_engine_seeds():
    # fuzz/tmcl_engine.cpp: per step int(0..7) (0: ticks 1..400), else an instruction
    # (tmcl_instructions.h): not a listed command -> the command byte; for SAP..RSAP and SGP..RSGP
    # not a table row -> the type byte; motor 0 or a byte; value kind 5 -> any int32.
    def instruction(f, command, type_, motor, value):
        f.int(1, 0, 7).bool(False).u8(command)
        if 5 <= command <= 12:
            f.bool(False)
        f.u8(type_)
        if motor == 0:
            f.bool(True)
        else:
            f.bool(False).u8(motor)
        f.int(5, 0, 5).i32(value)

    def ticks(f, n):
        f.int(0, 0, 7).int(n, 1, 400)

    def decode(frame):
        return frame[1], frame[2], frame[3], struct.unpack(">i", frame[4:8])[0]

    examples = manual_example_frames()
    for start in range(0, len(examples), 7):
        f = Fdp()
        for _, frame in examples[start:start + 7]:
            instruction(f, *decode(frame))
            ticks(f, 200)
        write("tmcl_engine", f"manual_examples_{start // 7}", f.data())
    # ROR / MVP / MST with motion in between (ror_example_sets_target_velocity_in_rpm).
    f = Fdp()
    for name, frame in examples:
        if name.split()[0] in ("ROR", "ROL", "MVP", "MST"):
            instruction(f, *decode(frame))
            ticks(f, 400)
    write("tmcl_engine", "motion", f.data())
    # A program downloaded and run: 132, SAP, WAIT TICKS, JA, 133, then 129 (run) and ticks.
    f = Fdp()
    for command, type_, motor, value in ((132, 0, 0, 0), (5, 4, 0, 1000), (4, 0, 0, 2000), (27, 0, 0, 10),
                                         (22, 0, 0, 1), (133, 0, 0, 0), (129, 1, 0, 0)):
        instruction(f, command, type_, motor, value)
    for _ in range(5):
        ticks(f, 400)
    instruction(f, 128, 0, 0, 0)
    write("tmcl_engine", "program", f.data())
    # Limits of a few axis and global parameters.
    f = Fdp()
    for command, type_, value in ((5, 4, 2**31 - 1), (5, 5, -1), (5, 140, 8), (9, 66, 255), (9, 67, 17), (5, 6, 0),
                                  (9, 66, 0), (10, 66, 0), (7, 4, 0), (8, 4, 0), (9, 84, 1), (11, 84, 0)):
        instruction(f, command, type_, 0, value)
    write("tmcl_engine", "limits", f.data())
    for name, text in TMCL_ENGINE_FINDINGS:
        write("tmcl_engine", name, base64.b64decode(text))


# 2026-12-08: the engine's device entry points indexed the axes with a motor beyond the last
# (fuzz/README.md "Findings").
TMCL_ENGINE_FINDINGS = [
    ("finding_2026_12_08_axis_parameter_of_motor_4", "AAAAgAUBAIAAAY8BAI8BAI8BAI8BAI8BFgABCgAAgAUBADsAGwHQBwCABQEABAAB6AMAgAT6BAAFAAEAAACABQEAhAAB"),
]


def tmcl_can_frame_seeds():
    # fuzz/tmcl_can_frames.cpp: per step int(0..9) (0: ticks 1..200); the ID (int(0..3) != 0: the
    # receive ID, else any 11-bit one); extended (int(0..3) == 0), then int(0..3) == 0: any 29-bit
    # ID; remote (int(0..15) == 0); the length (int(0..3) != 0: 7 + int(0..1), else 0..8); 8 bytes;
    # bool: replace the command byte.
    def frame(f, body, length=7, extended=False, rtr=False, cob_id=None, any_extended=None):
        f.int(1, 0, 9)
        if cob_id is None:
            f.int(1, 0, 3)
        else:
            f.int(0, 0, 3).int(cob_id, 0, 0x7FF)
        f.int(0 if extended else 1, 0, 3)
        if extended:
            if any_extended is None:
                f.int(1, 0, 3)
            else:
                f.int(0, 0, 3).int(any_extended, 0, 0x1FFFFFFF)
        f.int(0 if rtr else 1, 0, 15)
        if length in (7, 8):
            f.int(1, 0, 3).int(length - 7, 0, 1)
        else:
            f.int(0, 0, 3).int(length, 0, 8)
        f.eight(body).bool(False)

    def ticks(f, n):
        f.int(0, 0, 9).int(n, 1, 200)

    examples = manual_example_frames()
    for start in range(0, len(examples), 9):
        f = Fdp()
        for i, (_, request) in enumerate(examples[start:start + 9]):
            # 7 bytes (the serial frame without address and checksum), or 8 with the checksum as
            # PyTrinamic sends it; every third one extended.
            length = 8 if i % 2 else 7
            frame(f, request[1:1 + length], length, extended=i % 3 == 2)
            ticks(f, 50)
        write("tmcl_can_frames", f"manual_examples_{start // 9}", f.data())
    version = tmcl_frame(136, 0)
    f = Fdp()
    frame(f, version[1:8])
    frame(f, version[1:9], 8, extended=True)
    frame(f, tmcl_frame(136, 1)[1:8])
    frame(f, tmcl_frame(137, 0, 0, 1)[1:8])
    frame(f, tmcl_frame(6, 1)[1:8])
    write("tmcl_can_frames", "version_and_status", f.data())
    f = Fdp()  # nothing executes: other IDs, remote frames, short frames, an extended other ID
    frame(f, tmcl_frame(5, 4, 0, 1000)[1:8], cob_id=2)
    frame(f, tmcl_frame(5, 4, 0, 1000)[1:8], rtr=True)
    frame(f, tmcl_frame(9, 71, 0, 9)[1:8], extended=True, any_extended=0x1ABCDE01)
    frame(f, b"\x05\x04\x00", 3)
    frame(f, b"", 0)
    ticks(f, 200)
    frame(f, b"\x06", 1, extended=True)
    write("tmcl_can_frames", "nothing_executes", f.data())
    f = Fdp()  # SGP 71 / 70 move the IDs: the next frames follow GP 71 (docs/canopen.md)
    frame(f, tmcl_frame(9, 71, 0, 9)[1:8])
    frame(f, tmcl_frame(9, 70, 0, 10)[1:8])
    frame(f, tmcl_frame(10, 71, 0)[1:8], 8)
    frame(f, tmcl_frame(5, 4, 0, 1000)[1:8], cob_id=1)
    frame(f, tmcl_frame(255, 0, 0, 1234)[1:8])
    frame(f, tmcl_frame(10, 71, 0)[1:8])
    frame(f, tmcl_frame(137, 0, 0, 1234)[1:8])
    frame(f, tmcl_frame(10, 71, 0)[1:8])
    write("tmcl_can_frames", "id_change_reset_factory", f.data())


def le(value, size=4):
    return list((value & (2 ** (8 * size) - 1)).to_bytes(size, "little"))


def sdo_request(ccs_byte, index, sub, payload=()):
    return [ccs_byte, index & 0xFF, index >> 8, sub] + (list(payload) + [0, 0, 0, 0])[:4]


SAVE, LOAD = 0x65766173, 0x64616F6C


# 2026-11-26: 2703 sub 1 acknowledged "save" (0x65766173) and read 0 (issue 17).
CANOPEN_SDO_FINDINGS = [
    ("finding_2026_11_26_2703_sub1_reads_back",
     "AQMBAABkYW9sAhARIwEDAGV2YXMBJwMjAQMAZXZhcwQQECMBAwDNYW9sARARIwEDAAAAAADKysrKysrKysrKysrKysrKysrKysrKygEQ"
     "AAAAAAEAAgBzARAQIwAAIAEaACMBAwAAAAAAAhoAQAEDAAAAAYEBGAAjAQMAAAAAAgAaAC8BAwBgZAAgAhoAIwEDAGBBAPMAAAAtGgAB"
     "AQMAAAAE0gEQECMBAwM="),
]


def canopen_sdo_seeds():
    # fuzz/canopen_sdo.cpp: per step int(0..9): 0 NMT (bool: one of 01 02 80 81 82 by int(0..4),
    # else a byte; bool: node 0 = all, else this node), 1 any frame (ID 0..7FF, remote when
    # int(0..7) == 0, length 0..8, 8 bytes), 2 time (0..2 s), else an SDO request on 0x600 + node
    # (length: int(0..15) != 0 -> 8, else 0..8; 8 bytes; bool: keep the index).
    class Steps:
        def __init__(self):
            self.f = Fdp()

        def sdo(self, *data, length=8):
            self.f.int(3, 0, 9).length_and_eight(data, length).bool(False)
            return self

        def nmt(self, command):
            commands = [0x01, 0x02, 0x80, 0x81, 0x82]
            self.f.int(0, 0, 9).bool(True).int(commands.index(command), 0, 4).bool(True)
            return self

        def frame(self, cob_id, data, rtr=False):
            self.f.int(1, 0, 9).int(cob_id, 0, 0x7FF).int(0 if rtr else 1, 0, 7).int(len(data), 0, 8).eight(data)
            return self

        def wait(self, us):
            self.f.int(2, 0, 9).int(us, 0, 2_000_000)
            return self

    def seed(name, steps):
        write("canopen_sdo", name, steps.f.data())

    def crc16(data):
        crc = 0
        for b in data:
            crc ^= b << 8
            for _ in range(8):
                crc = ((crc << 1) ^ 0x1021) if crc & 0x8000 else crc << 1
                crc &= 0xFFFF
        return crc

    # Requests of tests/unit/core_canopen_sdo_server_test.cpp and core_canopen_sdo_block_test.cpp.
    seed("expedited_upload_identity", Steps().sdo(*sdo_request(0x40, 0x1000, 0)).sdo(*sdo_request(0x40, 0x1018, 1))
         .sdo(*sdo_request(0x40, 0x1018, 2)).sdo(*sdo_request(0x40, 0x1018, 3)).sdo(*sdo_request(0x40, 0x1018, 4))
         .sdo(*sdo_request(0x40, 0x1017, 0)).sdo(*sdo_request(0x40, 0x1001, 0)))
    seed("segmented_upload_names", Steps().sdo(*sdo_request(0x40, 0x1008, 0)).sdo(0x60).sdo(0x70)
         .sdo(*sdo_request(0x40, 0x1009, 0)).sdo(0x60).sdo(0x70).sdo(*sdo_request(0x40, 0x100A, 0)).sdo(0x60)
         .sdo(0x70).sdo(0x60))
    seed("toggle_errors", Steps().sdo(*sdo_request(0x40, 0x1008, 0)).sdo(0x70)
         .sdo(*sdo_request(0x21, 0x1016, 1, le(4))).sdo(0x17, 0x10, 0x27))
    seed("segmented_download_1016", Steps().sdo(*sdo_request(0x21, 0x1016, 1, le(4)))
         .sdo(((7 - 4) << 1) | 1, 0xE8, 0x03, 0x05, 0x00).sdo(*sdo_request(0x40, 0x1016, 1))
         .sdo(*sdo_request(0x20, 0x1016, 1)).sdo((7 - 2) << 1, 0x10, 0x00).sdo(0x10 | ((7 - 2) << 1) | 1, 0x07, 0x00))
    seed("segmented_download_sizes", Steps().sdo(*sdo_request(0x21, 0x1016, 1, le(4))).sdo(((7 - 3) << 1) | 1, 1, 2, 3)
         .sdo(*sdo_request(0x21, 0x1016, 1, le(5))).sdo(*sdo_request(0x21, 0x1016, 1, le(2)))
         .sdo(*sdo_request(0x21, 0x1016, 1, le(256))).sdo(*sdo_request(0x21, 0x1008, 0, le(3))))
    seed("expedited_download_sizes", Steps().sdo(*sdo_request(0x2B, 0x1017, 0, le(500, 2)))
         .sdo(*sdo_request(0x22, 0x1017, 0, [0xF4, 0x01, 0xAA, 0xBB])).sdo(*sdo_request(0x2F, 0x1017, 0, [5]))
         .sdo(*sdo_request(0x23, 0x1017, 0, le(1000))).sdo(*sdo_request(0x40, 0x1017, 0))
         .sdo(*sdo_request(0x2F, 0x1029, 1, [3])).sdo(*sdo_request(0x2F, 0x1029, 1, [2])))
    seed("unknown_and_read_only", Steps().sdo(*sdo_request(0x40, 0x5000, 0)).sdo(*sdo_request(0x40, 0x1018, 9))
         .sdo(*sdo_request(0x23, 0x1000, 0, le(1))).sdo(*sdo_request(0x21, 0x1008, 0, le(3)))
         .sdo(*sdo_request(0x23, 0x1018, 1, le(0x286))).sdo(*sdo_request(0x23, 0x5000, 0, le(1))))
    seed("store_and_restore", Steps().sdo(*sdo_request(0x23, 0x1010, 1, le(1234))).sdo(*sdo_request(0x23, 0x1010, 1, le(SAVE)))
         .sdo(*sdo_request(0x40, 0x1010, 1)).sdo(*sdo_request(0x23, 0x1011, 1, le(LOAD)))
         .sdo(*sdo_request(0x23, 0x1010, 4, le(SAVE))).sdo(*sdo_request(0x23, 0x2706, 1, le(SAVE)))
         .sdo(*sdo_request(0x23, 0x1011, 2, le(LOAD))).nmt(0x81))
    seed("pdo_mapping_in_cia301_order", Steps().sdo(*sdo_request(0x2F, 0x1A00, 0, [0]))
         .sdo(*sdo_request(0x23, 0x1800, 1, le(0x80000181))).sdo(*sdo_request(0x2F, 0x1A00, 0, [0]))
         .sdo(*sdo_request(0x23, 0x1A00, 1, le(0x60410010))).sdo(*sdo_request(0x23, 0x1A00, 2, le(0x60640020)))
         .sdo(*sdo_request(0x2F, 0x1A00, 0, [2])).sdo(*sdo_request(0x23, 0x1800, 1, le(0x181)))
         .sdo(*sdo_request(0x40, 0x1A00, 2)).sdo(*sdo_request(0x23, 0x1A00, 1, le(0x10000020))))
    seed("command_specifiers_and_sequence", Steps().sdo(0xE0).sdo(0x60).sdo(0x01).sdo(*sdo_request(0x40, 0x1008, 0))
         .sdo(0x01).sdo(0xA3).sdo(0xC1))
    seed("short_frames", Steps().sdo(0x40, 0x00, 0x10, length=3).sdo(length=0).sdo(*sdo_request(0x40, 0x1008, 0))
         .sdo(0x60, length=1).sdo(*sdo_request(0x40, 0x1000, 0)))
    seed("client_abort_and_stale_transfer", Steps().sdo(*sdo_request(0x40, 0x1008, 0))
         .sdo(0x80, 0x08, 0x10, 0, 0, 0, 0x04, 0x05).sdo(0x60).sdo(*sdo_request(0x40, 0x1008, 0))
         .sdo(*sdo_request(0x40, 0x1000, 0)).sdo(0x60))
    seed("timeouts", Steps().sdo(*sdo_request(0x40, 0x1008, 0)).wait(900_000).sdo(0x60).wait(999_000).wait(1000)
         .sdo(0x70).sdo(*sdo_request(0xC6, 0x1017, 0, le(2))).wait(1_500_000).sdo(0x81, 0xF4, 0x01))
    seed("remote_and_other_nodes", Steps().frame(0x602, sdo_request(0x40, 0x1000, 0))
         .frame(0x601, sdo_request(0x40, 0x1000, 0), rtr=True).frame(0x601, sdo_request(0x40, 0x1000, 0)[:4])
         .frame(0x000, [0x01, 0x00]).frame(0x080, []).frame(0x7E5, [0x5E]))
    name = b"TMCM-3216"
    seed("block_upload_device_name", Steps().sdo(*sdo_request(0xA4, 0x1008, 0, [127, 0])).sdo(0xA3)
         .sdo(0xA2, 2, 127).sdo(0xA1).sdo(*sdo_request(0xA0, 0x1008, 0, [127, 0])).sdo(0xA3).sdo(0xA2, 2, 127)
         .sdo(0xA1))
    seed("block_upload_resends", Steps().sdo(*sdo_request(0xA4, 0x1008, 0, [1, 0])).sdo(0xA3).sdo(0xA2, 0, 1)
         .sdo(0xA2, 1, 1).sdo(0xA2, 0, 2).sdo(0xA2, 1, 127).sdo(0xA1))
    seed("block_upload_errors", Steps().sdo(*sdo_request(0xA4, 0x1008, 0, [0, 0]))
         .sdo(*sdo_request(0xA4, 0x1008, 0, [128, 0])).sdo(*sdo_request(0xA4, 0x1008, 0, [127, 0])).sdo(0xA3)
         .sdo(0xA2, 5, 127).sdo(*sdo_request(0xA4, 0x1008, 0, [127, 0])).sdo(0xA3).sdo(0xA2, 2, 0)
         .sdo(*sdo_request(0xA4, 0x1008, 0, [127, 0])).sdo(0xA2, 0, 1).sdo(0xA1))
    seed("block_upload_protocol_switch", Steps().sdo(*sdo_request(0xA4, 0x1000, 0, [127, 4]))
         .sdo(*sdo_request(0xA4, 0x1008, 0, [127, 16])).sdo(0x60).sdo(0x70)
         .sdo(*sdo_request(0xA4, 0x1000, 0, [127, 0])).sdo(0xA3).sdo(0xA2, 1, 127).sdo(0xA1))
    value = [0xF4, 0x01]
    crc = crc16(value)
    seed("block_download_1017", Steps().sdo(*sdo_request(0xC6, 0x1017, 0, le(2))).sdo(0x81, *value)
         .sdo(0xC1 | (5 << 2), crc & 0xFF, crc >> 8).sdo(*sdo_request(0x40, 0x1017, 0))
         .sdo(*sdo_request(0xC2, 0x1016, 1, le(4))).sdo(0x81, 0xE8, 0x03, 0x05, 0x00).sdo(0xC1 | (3 << 2))
         .sdo(*sdo_request(0xC6, 0x1000, 0, le(4))))
    seed("block_download_errors", Steps().sdo(*sdo_request(0xC6, 0x1017, 0, le(2))).sdo(0x81, *value)
         .sdo(0xC1 | (5 << 2), 0x12, 0x34).sdo(*sdo_request(0xC6, 0x1017, 0, le(2))).sdo(0x81, *value)
         .sdo(0xC1 | (4 << 2), crc & 0xFF, crc >> 8).sdo(*sdo_request(0xC6, 0x1017, 0, le(2))).sdo(0x00, 1)
         .sdo(*sdo_request(0xC6, 0x1017, 0, le(2))).sdo(0x02, 1).sdo(0x81, *value).sdo(0x81, *value)
         .sdo(0xC1 | (5 << 2), crc & 0xFF, crc >> 8).sdo(*sdo_request(0xC6, 0x1017, 0, le(2))).sdo(0x81, *value)
         .sdo(0x82, *value).sdo(0x80, 0x17, 0x10))
    seed("nmt_during_transfers", Steps().sdo(*sdo_request(0x40, 0x1008, 0)).nmt(0x02).sdo(0x60).nmt(0x80).sdo(0x60)
         .sdo(*sdo_request(0xA4, 0x1008, 0, [127, 0])).sdo(0xA3).nmt(0x82).sdo(0xA2, 2, 127)
         .sdo(*sdo_request(0xC6, 0x1017, 0, le(2))).nmt(0x81).sdo(0x81, *value).nmt(0x01)
         .sdo(*sdo_request(0x40, 0x1008, 0)).sdo(0x60).sdo(0x70))
    # A CiA-402 bring-up as the manual's examples do it (tests/integration/test_cia402_manual.py):
    # mode, profile, controlwords, target, the statusword read back.
    seed("cia402_bring_up", Steps().sdo(*sdo_request(0x2F, 0x6060, 0, [1])).sdo(*sdo_request(0x23, 0x6081, 0, le(20000)))
         .sdo(*sdo_request(0x23, 0x6083, 0, le(50000))).sdo(*sdo_request(0x2B, 0x6040, 0, le(6, 2)))
         .sdo(*sdo_request(0x2B, 0x6040, 0, le(7, 2))).sdo(*sdo_request(0x2B, 0x6040, 0, le(0xF, 2)))
         .sdo(*sdo_request(0x23, 0x607A, 0, le(100000))).sdo(*sdo_request(0x2B, 0x6040, 0, le(0x1F, 2)))
         .sdo(*sdo_request(0x40, 0x6041, 0)).sdo(*sdo_request(0x2F, 0x6860, 0, [3]))
         .sdo(*sdo_request(0x2F, 0x7060, 0, [6])).sdo(*sdo_request(0x23, 0x2705, 0, [5])))
    # The conformance cases of issue 17 (tests/unit/core_tmcm3216_reset_test.cpp): 6060 and the
    # I/O written, NMT reset node, read back; 1005 with restricted identifiers and a new one while
    # producing.
    seed("conformance_reset_node_and_1005", Steps().sdo(*sdo_request(0x2F, 0x6060, 0, [1]))
         .sdo(*sdo_request(0x23, 0x2703, 2, le(0x000F0000))).sdo(*sdo_request(0x23, 0x2703, 1, le(0x00050000)))
         .sdo(*sdo_request(0x2B, 0x2711, 0, le(0x0101, 2))).nmt(0x81).sdo(*sdo_request(0x40, 0x6060, 0))
         .sdo(*sdo_request(0x40, 0x2703, 1)).sdo(*sdo_request(0x23, 0x1005, 0, le(0x000)))
         .sdo(*sdo_request(0x23, 0x1005, 0, le(0x701))).sdo(*sdo_request(0x23, 0x1005, 0, le(0x40000080)))
         .sdo(*sdo_request(0x23, 0x1005, 0, le(0x40000081))).sdo(*sdo_request(0x23, 0x1005, 0, le(0x80)))
         .sdo(*sdo_request(0x23, 0x1005, 0, le(0x81))).nmt(0x82).sdo(*sdo_request(0x40, 0x1005, 0)))
    # Inputs of findings (fuzz/README.md "Findings"), kept byte for byte: each replays its bug.
    for name, text in CANOPEN_SDO_FINDINGS:
        write("canopen_sdo", name, base64.b64decode(text))


def canopen_pdo_seeds():
    # fuzz/canopen_pdo.cpp: per step int(0..9): 0 NMT (int(0..5) of 01 01 02 80 81 82), 1 a remapping
    # in CiA-301's order (bool receive, PDO 0..3, axis 0..2, count 0..8, each entry: int(0..4) == 0
    # and bool false -> any UNSIGNED32, a receive PDO's transmission type: bool -> 255, else 1..3),
    # 2/3 one parameter write (not used here: it picks from the dictionary's rows), 4 SYNC (bool:
    # empty, else one byte), 5 time (0..200 ms), else an RPDO frame (PDO 0..3, axis 0..2,
    # int(0..7) == 0 -> any ID, length 0..8, 8 bytes).
    DUMMY_U8, DUMMY_U16, DUMMY_U32 = 0x00050008, 0x00060010, 0x00070020

    class Steps:
        def __init__(self):
            self.f = Fdp()

        def nmt(self, command):
            self.f.int(0, 0, 9).int([0x01, 0x01, 0x02, 0x80, 0x81, 0x82].index(command), 0, 5)
            return self

        def remap(self, receive, number, axis, entries, transmission=255):
            self.f.int(1, 0, 9).bool(receive).int(number, 0, 3).int(axis, 0, 2).int(len(entries), 0, 8)
            for entry in entries:
                self.f.int(0, 0, 4).bool(False).u32(entry)
            if receive:
                if transmission == 255:
                    self.f.bool(True)
                else:
                    self.f.bool(False).int(transmission, 1, 3)
            return self

        def sync(self):
            self.f.int(4, 0, 9).bool(True).u8(0)
            return self

        def wait(self, us):
            self.f.int(5, 0, 9).int(us, 0, 200_000)
            return self

        def rpdo(self, number, axis, data, cob_id=None):
            self.f.int(6, 0, 9).int(number, 0, 3).int(axis, 0, 2)
            if cob_id is None:
                self.f.int(1, 0, 7)
            else:
                self.f.int(0, 0, 7).int(cob_id, 0, 0x7FF)
            self.f.int(len(data), 0, 8).eight(data)
            return self

    def seed(name, steps):
        write("canopen_pdo", name, steps.f.data())

    # 2026-11-27: a TPDO given the EMCY's identifier 81h (fuzz/README.md "Findings": the target's
    # EMCY check, not the module, was wrong), kept byte for byte.
    write("canopen_pdo", "finding_2026_11_27_tpdo_on_the_emcy_identifier", base64.b64decode("gSDlAgAA"))

    # Default RPDOs of axis 0 (6040; 6040 + 6060; 6040 + 607A; 6040 + 60FF), then lengths off by one.
    seed("default_rpdos", Steps().nmt(0x01).rpdo(0, 0, [0x06, 0x00]).rpdo(1, 0, [0x0F, 0x00, 0x01])
         .rpdo(2, 0, [0x0F, 0x00, 0x10, 0x27, 0, 0]).rpdo(3, 0, [0x0F, 0x00, 0xE8, 0x03, 0, 0]).rpdo(0, 0, [0x06])
         .rpdo(1, 0, [0x0F, 0x00, 0x01, 0x02]).sync().wait(100_000))
    # python-canopen's PdoMap.save order (tests/integration/test_canopen_pdo.py), receive and transmit.
    seed("python_canopen_rpdo", Steps().remap(True, 0, 0, [0x60400010, 0x607A0020]).nmt(0x01)
         .rpdo(0, 0, [0x0F, 0x00, 0x40, 0x42, 0x0F, 0x00]).rpdo(0, 0, [0x0F, 0x00]).rpdo(0, 0, [0x0F] * 8)
         .wait(50_000))
    seed("python_canopen_tpdo_dummies", Steps().remap(False, 0, 0, [DUMMY_U32, DUMMY_U16]).nmt(0x01).wait(200_000)
         .remap(False, 1, 0, [DUMMY_U8, 0x60410010, 0x60610008]).wait(200_000).nmt(0x80))
    seed("axis_1_and_2", Steps().remap(True, 0, 1, [0x68400010, 0x68600008]).remap(True, 1, 2, [0x70400010, 0x707A0020])
         .nmt(0x01).rpdo(0, 1, [0x06, 0x00, 0x01]).rpdo(1, 2, [0x0F, 0x00, 0xFF, 0xFF, 0xFF, 0x7F]))
    seed("refusals", Steps().remap(True, 2, 0, [0x10000020]).remap(True, 3, 0, [0x607A0020] * 3)
         .remap(False, 2, 0, [0x60640020, 0x606C0020, 0x60410010]).remap(True, 0, 0, [0x12345678]).nmt(0x01)
         .rpdo(2, 0, [1, 2, 3, 4, 5, 6, 7, 8]).rpdo(3, 0, [0xFF] * 8))
    seed("synchronous_rpdo", Steps().remap(True, 2, 0, [0x60600008, 0x60FF0020], transmission=1).nmt(0x01)
         .rpdo(2, 0, [0x09, 0x10, 0x27, 0, 0]).sync().rpdo(2, 0, [0x7F, 0xFF, 0xFF, 0xFF, 0xFF]).sync()
         .remap(True, 2, 0, [0x60400010], transmission=2).rpdo(2, 0, [0x06, 0x00]).sync().sync())
    seed("stop_and_reset", Steps().nmt(0x01).nmt(0x02).rpdo(0, 0, [0x06, 0x00]).nmt(0x82).nmt(0x01)
         .rpdo(0, 0, [0x06, 0x00]).nmt(0x81).rpdo(0, 0, [0x06, 0x00], cob_id=0x201).wait(200_000))


def canopen_lss_seeds():
    # fuzz/canopen_lss.cpp: per step the length (int(0..15) != 0 -> 8, else 0..8), 8 bytes, then
    # int(0..9): 0 an NMT reset (bool: 81, else 82), 1 time (0..100 ms), 2..7 a listed command
    # (with the device's identity for 40..43 when bool), 8/9 the frame as it is.
    identity = (0x286, 3216, 0x00010004, 0)  # vendor, product, revision, serial (the rig's: 0)

    class Steps:
        def __init__(self):
            self.f = Fdp()

        def frame(self, *data, length=8):
            self.f.length_and_eight(data, length).int(8, 0, 9)
            return self

        def value(self, command, value, *more):
            return self.frame(command, *le(value), *more)

        def reset(self, node=True):
            self.f.length_and_eight([]).int(0, 0, 9).bool(node)
            return self

        def wait(self, us):
            self.f.length_and_eight([]).int(1, 0, 9).int(us, 0, 100_000)
            return self

    def seed(name, steps):
        write("canopen_lss", name, steps.f.data())

    # tests/unit/core_canopen_lss_test.cpp
    seed("inquire", Steps().frame(0x5A).frame(0x04, 1).frame(0x5A).frame(0x5B).frame(0x5C).frame(0x5D).frame(0x5E)
         .frame(0x04, 0).frame(0x5E))
    selective = Steps()
    for command, part in zip((0x40, 0x41, 0x42, 0x43), identity):
        selective.value(command, part)
    seed("switch_selective_configure_store", selective.frame(0x5E).frame(0x11, 5).frame(0x17).frame(0x04, 0)
         .reset(False).frame(0x5E))
    seed("switch_selective_wrong_order", Steps().value(0x41, 3216).value(0x40, 0x286).value(0x43, 0)
         .value(0x42, 0x00010004).value(0x43, 0).value(0x43, 1))
    seed("configure_node_id_errors", Steps().frame(0x11, 5).frame(0x04, 1).frame(0x11, 0).frame(0x11, 128)
         .frame(0x11, 254).frame(0x11, 255).frame(0x11, 127).frame(0x11, 1).frame(0x04, 0).reset(True))
    timing = Steps().frame(0x04, 1)
    for table in range(9):
        timing.frame(0x13, 0, table)
    seed("configure_bit_timing", timing.frame(0x13, 1, 0).frame(0x13, 0, 3).frame(0x15, 100, 0).wait(50_000)
         .wait(60_000).wait(100_000).frame(0x5E).reset(True))
    # Fastscan as python-canopen runs it (fastscan_finds_an_unconfigured_node...): the node made
    # unconfigured first (node ID 255, reset communication).
    scan = Steps().frame(0x04, 1).frame(0x11, 255).frame(0x04, 0).reset(False).frame(0x51, 0, 0, 0, 0, 0x80, 0, 0)
    for sub, part in enumerate(identity):
        guess = 0
        for bit in range(31, -1, -1):
            scan.value(0x51, guess, bit, sub, sub)
            guess |= part & (1 << bit)
        scan.value(0x51, part, 0, sub, (sub + 1) & 3)
    seed("fastscan", scan.frame(0x11, 33).frame(0x17).frame(0x04, 0))
    seed("fastscan_wrong_part", Steps().frame(0x04, 1).frame(0x11, 255).frame(0x04, 0).reset(False)
         .frame(0x51, 0, 0, 0, 0, 0x80, 0, 0).frame(0x51, 0x90, 0x0C, 0, 0, 0, 1, 2).frame(0x51, 0x86, 0x02, 0, 0, 0, 0, 1)
         .frame(0x51, 0x91, 0x0C, 0, 0, 0, 1, 2).frame(0x51, 0x90, 0x0C, 0, 0, 0, 1, 2).frame(0x51, 0, 0, 0, 0, 33, 2, 2)
         .frame(0x51, 0, 0, 0, 0, 0, 4, 0).frame(0x51, 0, 0, 0, 0, 0x80, length=6))
    seed("short_frames", Steps().frame(0x04, 1, length=2).frame(0x5E, length=1).frame(length=0).frame(0x04, 1)
         .frame(0x11, 7, length=7).frame(0x5E))


def sdo_seeds():
    # Fixed random bytes besides, as before: varied integers for the provider.
    rng = random.Random(3216)
    for n in (16, 64, 256, 1024):
        for target in ("canopen_sdo", "tmcl_engine", "canopen_pdo", "canopen_lss", "tmcl_can_frames"):
            write(target, f"random_{n}", bytes(rng.randrange(256) for _ in range(n)))
    canopen_sdo_seeds()
    canopen_pdo_seeds()
    canopen_lss_seeds()
    tmcl_engine_seeds()
    tmcl_can_frame_seeds()
    tmcm1636_canopen_seeds()


# 2026-11-27: the eight_point_ramp campaign's findings (fuzz/README.md "Findings").
EIGHT_POINT_RAMP_FINDINGS = [
    # A profile changed to VMAX 0 while moving: the last braking tick rounded past 0 into a
    # reversal (EightPointRamp.braking_to_rest_never_rounds_past_zero_into_a_reversal).
    ("finding_2026_11_27_braking_rounds_past_zero",
     "I///O8kA/////////3nmDsN/kiRCQgAAQkK8AAAF/QAF/QABAAAAAAAAAAX9BQAAAAX9Bg=="),
    ("finding_2026_11_27_last_q32_unit_of_a_crawl",
     "Nvox8M76hBMhY7OWzGjwyknJHtTMWmy1KwD+asWKbC2pkuwXyqCPIWOz/////////////xUpclJdysp4AAC4pTjH4KN5c5VYBwAA"
     "AQAAYwH5N4d0zj1nOs+8s0cdv0ncCw=="),
    ("finding_2026_11_27_tvmax_stalls_on_a_fraction",
     "ODGWCH2MU2KB7VYABBX8N4y6YHNCiiFroCujHwvbx1wUWO44SCUo4nmfrwotGPtS5QEcbiNiL/1WAAQV/DeMumCNvXXelF9LM9ES"
     "yVEQj1YqOea21B3vmU5w+tcgN898////////////////wv8CAAACAAAAnEcdQEncCw=="),
    ("finding_2026_11_27_on_the_target_with_a_residual_speed",
     "+jHVz5pp0c9XA/P0VlqF+DEAAAAAAAAAAE30AJWH4k2/PAstAE30AJWG4v/////////xTb88Cy2gkJiTv5Myi7P1qrb755WzGcDA"
     "////q8DAwMDAwMDAwMDAwMDAwETFp0IAAAjSKGXPs0e8QB1J3As="),
    ("finding_2026_11_27_braking_curve_rounds_past_the_target",
     "+jHVz5pp0c9XA/Na9IVW+DEAAAAAAKNuG+z0AJWH4k2/PAstAE30CZWG4v////////8hTb88Cy2gkJiTv5Myi7P1qrb755WzGcDA"
     "////q8DAwMDAwMDAwMDAwMDAwETFp0IAAAjSKGXPs0e8QB1J3As="),
]


# 2026-11-27: 606C of a csp set-point half the counter away overflowed int32 (fuzz/README.md "Findings").
TMCM3216_DRIVE_FINDINGS = [
    ("finding_2026_11_27_velocity_actual_beyond_int32",
     "/tzJQABKsgSp9C3Sv+nWU4UhencVpnMcjamMnvD35IFg++HON3Jb0VfIjl+tfSoGAgAAAAEAAQACAAEA//8AAAAAAAD/////AAAA"
     "GgAVEiQZAAAAAIEAAACA////fwDIAAAAAAAAAMgAAADIAAAAyAAApstIET8Eu/QKjA9SGdYRUFq+0lX0SJeOZgNhZhifZS7x1W9X"
     "P2ycDS9Ogr7G7wmDYZGfGkfHqzMnygAAx+ZZyW0yf3vk4EYJ/zPqK3V8jD81m66vh9E+ZYpESe/CrccwV6oPYULqv+q6n/VGSQlK"
     "xpUAAMgAAADIAAA9StSF8L2NGSQSFbnSPCAKxQNyMqi7JZLnNz0U2EMf"),
    # 2026-11-27: full steps (2000 = 0) taken at switch-off snapped the field to the nearest full step
    # (Tmcm3216Stepper.NewResolutionNearTheEndOfTheElectricalCircleKeepsTheField).
    ("finding_2026_11_27_new_resolution_snapped_the_field", "P5k7BdglckktlwcCcbCVGvVlOCZSqNijGVBfbEBNc/kH"),
]


# 2026-11-27: SAP 255 1 left AP 17 (set in TMC457 units) beyond the range of µsteps/s² (fuzz/README.md
# "Findings"; Tmcm142Parameters.a_switch_to_unit_mode_1_lowers_accelerations_beyond_its_range).
TMCM142_ENGINE_FINDINGS = [
    ("finding_2026_11_27_unit_mode_1_acceleration_beyond_range", "DX/34wQVE8e7T4sFJFE="),
]


# Inputs of the tmcm1636_canopen findings (fuzz/README.md "Findings"), kept byte for byte.
TMCM1636_CANOPEN_FINDINGS = [
    # 2026-12-07: 2703 sub 1 acknowledged a write without a mask and read 0
    # (Tmcm1636Canopen.physical_outputs_read_back_as_written_and_the_mask_decides_what_switches).
    ("finding_2026_12_07_2703_sub1_reads_back", "ASMAIdylBCEA"),
    # 2026-12-07: csv at 1.6e9 rpm took the axis past the drive's 32-bit wrap; the demand converted whole
    # then moved the ideal motor 2^29 counts with the driver off
    # (Tmcm1636Canopen.a_position_mode_after_the_drive_position_wrapped_holds_the_motor_where_it_is).
    ("finding_2026_12_07_demand_past_the_drive_wrap", "z8F5Fv////////+aF9WN8wEMAgIAAAECAD0bRJ/8AAAA3TKixvT0"),
    # 2026-12-07: enable, 2080:2 and a quick stop between two drive runs; the stale demand moved the unpowered
    # ideal motor (Tmcm1636Canopen.the_ideal_motor_stands_while_the_power_stage_is_off).
    ("finding_2026_12_07_demand_handed_to_the_unpowered_axis", "93cTAk2hAgAFGRIoNAEZEgwAACADEgwAIAMBBQEAMw=="),
    # 2026-12-07: homing 35 attained at the write, then disable voltage; the counter set to the home offset with
    # the driver off (Tmcm1636Canopen.homing_35_takes_the_home_offset_at_once_without_a_following_error).
    ("finding_2026_12_07_homing_35_then_disable_voltage", "/w0DARIHAAESEgMBDwEEDAEAAAEAEg=="),
]


def tmcm1636_canopen_seeds():
    # fuzz/tmcm1636_canopen.cpp (keep these lists as its kDriveObjects, kControlwords, kModes,
    # kHomingMethods): u8 the bring-up (bits 0-3 the mode, index into MODES, 11..15 none; 4 the
    # profile; 5 enable; 6 no NMT start), u8 the motor (bits 0-2 all set: the physical one), then per
    # step int(0..14): 0 NMT (int(0..6) of 01 01 01 80 02 82 81, bool: all nodes), 1-3 a drive
    # object (its index in DRIVE, the sub-index in its range, then the value: a controlword, mode or
    # homing method by its index, else bool -> -200000..200000, else any INTEGER32), 4 any object
    # of the table (not used here: it picks from the table's rows), 5 a raw SDO request (length as
    # the CANopen targets', 8 bytes, bool: a real object's index, not used here), 6 an RPDO
    # (int(0..3) RPDO 1..4, length: int(0..7) == 0 -> 0..8, else 2, 3 or 6; 8 bytes; the
    # controlword by its index), 7 SYNC (int(0..7) == 0 -> one byte; a byte), 8 node guarding
    # (int(0..7) == 0 -> another node 0..127; int(0..7) != 0 -> remote; length 0..8; int(0..3) of
    # 00 04 05 7F), 9 LSS (length, 8 bytes, bool -> int(0..14) of the commands), 10 any identifier,
    # 11 a board input (not used here), 12-14 ticks (1..1000).
    DRIVE = [(0x6040, 0, 0), (0x6040, 0, 0), (0x6040, 0, 0), (0x6060, 0, 0), (0x6060, 0, 0), (0x607A, 0, 0),
             (0x60FF, 0, 0), (0x6071, 0, 0), (0x6081, 0, 0), (0x6083, 0, 0), (0x6084, 0, 0), (0x6085, 0, 0),
             (0x6098, 0, 0), (0x6099, 1, 2), (0x609A, 0, 0), (0x607C, 0, 0), (0x605A, 0, 0), (0x6072, 0, 0),
             (0x60C2, 1, 2), (0x6065, 0, 0), (0x6067, 0, 0), (0x607D, 1, 2), (0x2005, 0, 0), (0x2057, 0, 0),
             (0x2058, 0, 0), (0x2080, 2, 2)]
    CONTROLWORDS = [0x0006, 0x0007, 0x000F, 0x0000, 0x0002, 0x0007, 0x0080, 0x001F, 0x000F, 0x010F, 0x005F, 0x003F,
                    0x000B, 0x008F, 0x002F]
    MODES = [1, 3, 6, 8, 9, 10, 0, -1, 2, 7, 4]
    METHODS = [17, 18, 19, 21, 35, 0, 1, 37, -1]
    PP, PV, HM, CSP, CSV, CST = range(6)
    PROFILE, ENABLE, NO_START = 0x10, 0x20, 0x40

    class Steps:
        def __init__(self, bring_up, physical=False):
            self.f = Fdp().u8(bring_up).u8(0xFF if physical else 0x00)

        def nmt(self, command, all_nodes=True):
            self.f.int(0, 0, 14).int([0x01, 0x01, 0x01, 0x80, 0x02, 0x82, 0x81].index(command), 0, 6).bool(all_nodes)
            return self

        def write(self, index, value, sub=0):
            i = next(n for n, (x, lo, hi) in enumerate(DRIVE) if x == index and lo <= sub <= hi)
            _, lo, hi = DRIVE[i]
            self.f.int(1, 0, 14).int(i, 0, len(DRIVE) - 1).int(sub, lo, hi)
            if index == 0x6040:
                self.f.int(CONTROLWORDS.index(value), 0, len(CONTROLWORDS) - 1)
            elif index == 0x6060:
                self.f.int(MODES.index(value), 0, len(MODES) - 1)
            elif index == 0x6098:
                self.f.int(METHODS.index(value), 0, len(METHODS) - 1)
            elif -200_000 <= value <= 200_000:
                self.f.bool(True).int(value, -200_000, 200_000)
            else:
                self.f.bool(False).i32(value)
            return self

        def sdo(self, *data, length=8):
            self.f.int(5, 0, 14).length_and_eight(data, length).bool(False)
            return self

        def rpdo(self, number, controlword, data=(), length=None):
            self.f.int(6, 0, 14).int(number - 1, 0, 3)
            if length is None:
                length = {1: 2, 2: 3, 3: 6, 4: 6}[number]
            if length in (2, 3, 6):
                self.f.int(1, 0, 7).int([2, 3, 6].index(length), 0, 2)
            else:
                self.f.int(0, 0, 7).int(length, 0, 8)
            self.f.eight([0, 0] + list(data)).int(CONTROLWORDS.index(controlword), 0, len(CONTROLWORDS) - 1)
            return self

        def sync(self):
            self.f.int(7, 0, 14).int(1, 0, 7).u8(0)
            return self

        def guard(self, remote=True):
            self.f.int(8, 0, 14).int(1, 0, 7).int(1 if remote else 0, 0, 7).int(0, 0, 8).int(0, 0, 3)
            return self

        def lss(self, command, *data):
            self.f.int(9, 0, 14).length_and_eight([command] + list(data)).bool(False)
            return self

        def frame(self, cob_id, data, rtr=False):
            self.f.int(10, 0, 14).int(cob_id, 0, 0x7FF).int(0 if rtr else 1, 0, 7).int(len(data), 0, 8).eight(data)
            return self

        def ticks(self, n):
            while n > 0:
                self.f.int(12, 0, 14).int(min(n, 1000), 1, 1000)
                n -= 1000
            return self

    def seed(name, steps):
        write("tmcm1636_canopen", name, steps.f.data())

    # The sequences of tests/unit/core_tmcm1636_canopen_test.cpp and PyTrinamic's TMCM-1636 CANopen
    # examples (tests/integration/test_tmcm1636_canopen_examples.py), on the ideal motor and on the
    # physical one.
    def pv_run(physical):
        return (Steps(PV | PROFILE | ENABLE, physical).write(0x60FF, 500).ticks(1500).write(0x60FF, -300).ticks(500)
                .write(0x6040, 0x010F).ticks(300).write(0x6040, 0x000F).write(0x6040, 0x0002).ticks(500)
                .sdo(0x40, 0x41, 0x60, 0).sdo(0x40, 0x6C, 0x60, 0))
    seed("pv_run", pv_run(False))
    seed("pv_run_physical", pv_run(True))

    def pp_move(physical):
        return (Steps(PP | PROFILE | ENABLE, physical).write(0x607A, 100_000).write(0x6040, 0x001F).ticks(1200)
                .write(0x6040, 0x000F).write(0x607A, -50_000).write(0x6040, 0x005F).ticks(1500)
                .write(0x6040, 0x000F).write(0x607A, 40_000).write(0x6040, 0x003F).ticks(1000)
                .sdo(0x40, 0x64, 0x60, 0).sdo(0x40, 0x41, 0x60, 0))
    seed("pp_move", pp_move(False))
    seed("pp_move_physical", pp_move(True))
    csp = Steps(CSP | PROFILE | ENABLE)
    for k in range(1, 30):
        csp.write(0x607A, 600 * k).ticks(20)
    seed("csp_by_sdo", csp.write(0x60C2, 5, sub=1).sync().write(0x607A, 20_000).sync().ticks(200))
    seed("cst", Steps(CST | PROFILE | ENABLE).write(0x6071, 300).ticks(400).write(0x6072, 100).write(0x6071, -500)
         .ticks(400).write(0x6040, 0x0002).ticks(400).write(0x6040, 0x0000))
    seed("homing", Steps(HM | PROFILE).write(0x2005, 0).write(0x6098, 17).write(0x6040, 0x0006)
         .write(0x6040, 0x0007).write(0x6040, 0x000F).write(0x6040, 0x001F).ticks(1000).write(0x6040, 0x000F)
         .write(0x6098, 35).write(0x607C, 1234).write(0x6040, 0x001F).ticks(200).sdo(0x40, 0x64, 0x60, 0)
         .write(0x6040, 0x0080).write(0x6040, 0x0000))
    save, load = le(SAVE), le(LOAD)
    seed("store_restore", Steps(PV | NO_START).sdo(0x23, 0x03, 0x20, 0, *le(1500)).sdo(0x23, 0x83, 0x60, 0, *le(700))
         .sdo(0x23, 0x10, 0x10, 3, *save).sdo(0x23, 0x10, 0x10, 3, *le(0x1234)).nmt(0x81).sdo(0x40, 0x03, 0x20, 0)
         .sdo(0x23, 0x11, 0x10, 1, *load).sdo(0x23, 0x06, 0x27, 1, *save).sdo(0x2F, 0x05, 0x27, 0, 5)
         .sdo(0x23, 0x10, 0x10, 2, *save).nmt(0x81).sdo(0x23, 0x11, 0x10, 1, *load).nmt(0x81))
    seed("node_guarding", Steps(0x0F).sdo(0x2B, 0x0C, 0x10, 0, *le(20, 2)).sdo(0x2F, 0x0D, 0x10, 0, 3).guard()
         .ticks(40).guard().guard().ticks(1000).guard().nmt(0x02).guard().nmt(0x82).guard().ticks(20).guard()
         .sdo(0x2B, 0x17, 0x10, 0, *le(10, 2)).guard().ticks(30).guard(remote=False))
    seed("lss_and_other_frames", Steps(PV | PROFILE | ENABLE).lss(0x04, 1).lss(0x5A).lss(0x5E).lss(0x11, 5)
         .lss(0x40, 0x86, 0x02).frame(0x7E5, [0x04, 0x00]).frame(0x000, [0x81, 0x01]).sync().rpdo(1, 0x000F)
         .rpdo(4, 0x000F, le(100)).rpdo(3, 0x001F, le(5000)).rpdo(2, 0x000F, [1]).ticks(200))
    seed("outputs_and_boot_mode", Steps(0x0F | NO_START).sdo(0x23, 0x03, 0x27, 2, *le(1)).sdo(0x23, 0x03, 0x27, 1, *le(3))
         .sdo(0x23, 0x03, 0x27, 1, *le(SAVE)).sdo(0x40, 0x03, 0x27, 1).sdo(0x23, 0xFF, 0x5F, 0, *le(0x12345678))
         .sdo(0x23, 0xFF, 0x5F, 0, *le(7)).sdo(0x40, 0xFF, 0x5F, 0))
    rng = random.Random(1636)
    for n in (64, 256, 1024, 4096):
        for k in range(2):
            write("tmcm1636_canopen", f"random_{n}_{k}", bytes(rng.randrange(256) for _ in range(n)))
    for name, text in TMCM1636_CANOPEN_FINDINGS:
        write("tmcm1636_canopen", name, base64.b64decode(text))

def engine_seeds():
    # The ramp, homing, TMCM-3216 drive and TMCM-142 engine targets read FuzzedDataProvider input
    # too; their own generator, so that the seeds of the targets above stay as they are.
    rng = random.Random(402)
    for n in (64, 256, 1024, 4096):
        for target in ("eight_point_ramp", "cia402_homing", "tmcm3216_drive", "tmcm142_engine"):
            for k in range(2):
                write(target, f"random_{n}_{k}", bytes(rng.randrange(256) for _ in range(n)))
    # Inputs of findings, kept byte for byte: each replays its bug.
    for name, text in EIGHT_POINT_RAMP_FINDINGS:
        write("eight_point_ramp", name, base64.b64decode(text))
    for name, text in TMCM3216_DRIVE_FINDINGS:
        write("tmcm3216_drive", name, base64.b64decode(text))
    for name, text in TMCM142_ENGINE_FINDINGS:
        write("tmcm142_engine", name, base64.b64decode(text))
    # The TMCM-3216 TMCL engine: a generator of its own, so that the seeds above stay as they are.
    rng_tmcl3216 = random.Random(3216)
    for n in (64, 256, 1024, 4096):
        for k in range(2):
            write("tmcm3216_tmcl_engine", f"random_{n}_{k}", bytes(rng_tmcl3216.randrange(256) for _ in range(n)))
    # tmcm3216_drive's last byte is its bring-up: bits 0-2 the axes enabled, 3-5 the mode
    # (pp, pv, hm, csp, csv, ...), 6 no NMT start, 7 limit switches off (2005 = 3).
    for bring_up in (0x07, 0x0F, 0x17, 0x1F, 0x27, 0x81, 0x89, 0x91, 0x99, 0xA1, 0xC7):
        write("tmcm3216_drive", f"bring_up_{bring_up:02x}", bytes(rng.randrange(256) for _ in range(512)) + bytes([bring_up]))


def can_text_seeds():
    socketcand = [
        "< open vcan0 >< rawmode >",
        "< send 601 8 40 00 10 00 00 00 00 00 >",
        "< send 601 8 23 17 10 00 e8 03 00 00 >< send 000 2 01 00 >",
        "< send 1FFFFFFF 0 >< send 00000123 1 ff >< send 7FF 3 1 2 3 >",
        "garbage < send 601 9 1 2 3 4 5 6 7 8 9 > <unterminated < send 080 0 >",
    ]
    for i, text in enumerate(socketcand):
        write("socketcand_stream", f"stream_{i}", bytes([1 + i * 7]) + text.encode())
    # socketcand_session: byte 0 the chunk sizes, byte 1 a bus frame every n-th chunk, byte 2 the
    # connection closing from its n-th write (0: never); then the client's stream.
    sessions = [
        (0, 1, 0, "< open can0 >< rawmode >< send 601 8 40 00 10 00 00 00 00 00 >< send 601 8 40 08 10 00 00 00 00 00 >"),
        (3, 2, 0, "< open can0 >< rawmode >< send 603 8 40 18 10 2 0 0 0 0 >< echo >< bcmmode >< send 000 2 01 00 >"
                  "< rawmode >< rawmode >< bcmmode >"),
        (7, 1, 0, "< rawmode >< send 601 1 00 >< echo >< open >< open a b >< open vcan0 >< open vcan0 >< echo >"),
        (1, 3, 0, "< open can0 >< send 1FFFFFFF 0 >< send 00000123 1 ff >< send 7FF 3 1 2 3 >< send 601 9 1 2 3 4 5 6 7 8 9 >"
                  "< send 601 2 40 >< send xyz 0 >< send 601 1 100 >< send >< frobnicate >< rawmode now >"),
        (5, 1, 4, "< open can0 >< rawmode >< echo >< echo >< echo >< send 601 0 >"),
        (2, 1, 0, "garbage < open can0 > <unterminated < rawmode > > < " + "x" * 300 + " >< echo >"),
        (64, 1, 0, "<open can0><rawmode><send 080 0><bcmmode><echo>\r\n<  echo  >"),
    ]
    for i, (chunk, frames, close, text) in enumerate(sessions):
        write("socketcand_session", f"session_{i}", bytes([chunk, frames, close]) + text.encode())
    slcan = [
        "\r\r\rS8\rO\rt6018400010000000000\rV\rN\rF\rC\r",
        "S4\rO\rT000006012AABB\rr6010\rR000001230\rZ1\rC\r",
        "O\rL\rt601\rt60190011223344556677889\r" + "t" * 70 + "\rC\rs0314\r",
        "O\rt0000\rt7FF812345678ABCDEF01\r\n\0C\r",
    ]
    for i, text in enumerate(slcan):
        write("slcan_stream", f"session_{i}", bytes([1 + i * 5]) + text.encode())


def text_file_seeds():
    # scenario_file: byte 0 picks the signal table (0 TMCM-1636, 1 TMCM-142, 2 TMCM-3216).
    write("scenario_file", "example",
          "\0# supply dip while the home switch closes\n\n2.0   VSUPPLY 26.5   # after the dip\n0.5\tGPI0 1\n"
          "   1e-3 ref_h 1\r\n0.5 GPI0 0\n")
    write("scenario_file", "motor_signals", "\0" "0 LOAD_TORQUE 0.2\n0.1 TEMP 80\n0.2 AI0 5\n1e9 GPI3 1\n")
    write("scenario_file", "tmcm142_axis", "\1# axis.scn (docs/tmcm-142.md)\n0    REF_L_AT  -0.25\n0    REF_R_AT   1.5\n"
          "0.05 BLOCKED    1\n0 ENCODER_CPR 4000\n0.01 IN0 1\n0.02 AIN0 2048\n")
    write("scenario_file", "tmcm3216_shutdown", "\2# shutdown.scn (docs/tmcm-3216-drive.md)\n5.0 ENABLE 0\n6 ENABLE 1\n"
          "0 AXIS0_REF_L_AT -0.5\n0 axis2_ref_r 1\n0.1 AXIS1_LOAD_TORQUE 0.3\n0.2 DIO3 1\n0.3 AIN1 4095\n"
          "1 AXIS0_ENCODER_CPR 8000\n1 AXIS1_BRAKE 1\n1 AXIS3_BRAKE 1\n")
    write("scenario_file", "tmcm3216_axes", "\2" "0 AXIS0_REF_H_FROM 0.1\n0 AXIS0_REF_H_TO 0.2\n0.5 AXIS2_DRIVER_TEMP 130\n"
          "0.5 AXIS1_OPEN_COIL_A 1\n0.6 AXIS1_SHORT 1\n0.7 VSUPPLY 9\n0.8 AXIS0_POSITION_REV 1\n")
    write("motor_description", "example", """{
  "name": "my-motor", "source": "datasheet XYZ rev 3", "type": "bldc", "pole_pairs": 7,
  "kv_rpm_per_v": 270, "resistance_ohm": 0.05, "inductance_h": 2e-5, "rotor_inertia_kgm2": 1e-4,
  "viscous_friction_nm_s": 5e-5, "coulomb_friction_nm": 0.01, "initial_angle_deg": 17,
  "hall": {"present": true, "offset_deg": 0, "inverted": false, "reversed": false},
  "abn_encoder": {"present": true, "counts_per_rev": 8192, "index_deg": 0, "reversed": false},
  "absolute_encoder": {"present": false, "bits": 12, "offset_deg": 0, "reversed": false},
  "brake": {"present": false, "holding_torque_nm": 0.5, "pull_in_duty_percent": 50,
            "drop_out_duty_percent": 8, "time_constant_s": 0.015},
  "supply": {"voltage_v": 48, "source_resistance_ohm": 0.05, "capacitance_f": 1e-3,
             "brake_resistor_ohm": 5, "regenerative": false},
  "axis_parameters": {"10": 7, "14": 3, "15": 2, "25": 1, "100": 8192}
}
""")
    write("motor_description", "dc", '{"name": "dc", "type": "dc", "torque_constant_nm_per_a": 0.05}\n')
    write("motor_description", "startup", """{
  "name": "named", "pole_pairs": 4, "torque_constant_nm_per_a": 0.035,
  "startup": {"max_current_ma": 2000, "open_loop_current_ma": 1000, "commutation": "hall",
              "position_sensor": "abn_encoder", "hall_interpolation": true, "encoder_alignment": "hall",
              "brake_chopper_voltage_v": 52, "current_p": 461, "current_i": 3932, "velocity_p": 1200,
              "velocity_i": 1200, "position_p": 300},
  "axis_parameters": {"11": 1500}
}
""")
    # Finding of 2026-11-27 (fuzz/README.md "Findings"): a torque constant that gives a flux
    # linkage outside the range the description is written back with.
    write("motor_description", "kt_gives_flux_out_of_range", """{
  "name": "named", "pole_pairs": 2, "torque_constant_nm_per_a": 50.35,
  "startup": {"max_current_ma": 1999, "open_loop_current_ma": 1000, "brake_chopper_voltage_v": 52, "current_p": 1200,
              "velocity_i": 1200, "position_p": 150},
  "axis_parameters": {"11": 1500}
}
""")


def tmcm142_board_seeds():
    # Byte 0: bit 0 physical motor (the JSON), bits 1-3 the motion (0 ROR, 1 ROL, 2/3 MVP +/-,
    # 4 RFS, 5 RFS with another mode, else none), bits 4-7 its size; then motor JSON, NUL, scenario.
    motors = [
        "",
        '{"base": "nema17"}',
        '{"base": "nema23", "name": "bench", "resistance_ohm": 0.8, "inductance_h": 0.0021, '
        '"torque_constant_nm_per_a": 0.35, "detent_torque_nm": 0, "rotor_inertia_kg_m2": 2.7e-5, '
        '"friction_torque_nm": 0.01, "rated_current_a": 2.8, "viscous_friction_nm_s": 0, '
        '"full_steps_per_revolution": 400}',
    ]
    scenarios = [
        "# axis.scn (docs/tmcm-142.md)\n0    REF_L_AT  -0.25\n0    REF_R_AT   1.5\n0.05 BLOCKED    1\n",
        "0 REF_H_FROM 0.01\n0 REF_H_TO 0.02\n0.02 LOAD_TORQUE 0.5\n0.03 LOAD_INERTIA 1e-4\n",
        "0 ENCODER_CPR 4000\n0.01 ENCODER_INDEX_AT 0.5\n0.02 ENCODER_REVERSED 1\n0.04 ENCODER_FAULT 1\n"
        "0.06 ENCODER_FAULT 0\n",
        "0 VSUPPLY 12\n0.01 IN0 1\n0.02 AIN0 2048\n0.03 REF_R 1\n0.04 REF_R 0\n0.05 VSUPPLY 48\n",
    ]
    for i, (control, motor, scenario) in enumerate([
            (0x00, 0, 0), (0x13, 2, 1), (0x25, 1, 2), (0x07, 2, 0), (0x09, 0, 0), (0x1B, 1, 0),
            (0x31, 2, 3), (0x0E, 0, 2), (0x41, 2, 2)]):
        write("tmcm142_board", f"seed_{i}", bytes([control]) + motors[motor].encode() + b"\0" + scenarios[scenario].encode())


def eeprom_seeds(motwin):
    # eeprom_image: byte 0 picks the module (0 TMCM-1636, 1 TMCM-142, 2 TMCM-3216), the rest is
    # its image file, starting from the factory image a real `motwin serve` writes.
    if not motwin:
        return
    for selector, module, endpoint in ((0, "tmcm-1636", ["--tmcl-tcp", "127.0.0.1:0"]),
                                       (1, "tmcm-142", ["--tmcl-tcp", "127.0.0.1:0"]),
                                       (2, "tmcm-3216", ["--can", "socketcand:127.0.0.1:0"])):
        with tempfile.TemporaryDirectory() as tmp:
            proc = subprocess.Popen([motwin, "serve", "--module", module, "--state-dir", tmp] + endpoint,
                                    stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
            for line in proc.stdout:
                if line.strip() == b"ready":
                    break
            proc.send_signal(signal.SIGTERM)
            proc.wait(timeout=15)
            with open(os.path.join(tmp, f"{module}.eeprom"), "rb") as f:
                good = f.read()
        prefix = bytes([selector])
        write("eeprom_image", f"{module}_factory", prefix + good)
        flipped = bytearray(good)
        flipped[min(64 + 43 * 4, len(good) - 1)] ^= 0xFF
        write("eeprom_image", f"{module}_payload_flipped", prefix + bytes(flipped))
        write("eeprom_image", f"{module}_truncated", prefix + good[:len(good) // 2])
        write("eeprom_image", f"{module}_header_only", prefix + good[:64])
        # Valid header CRC over a payload with another size: gets past the first checks.
        header = bytearray(good[:64])
        struct.pack_into("<I", header, 52, 16)
        struct.pack_into("<I", header, 60, zlib.crc32(bytes(header[:60])) & 0xFFFFFFFF)
        write("eeprom_image", f"{module}_other_payload_size", prefix + bytes(header) + good[64:80])
    # A TMCM-142 image of NVM layout 1 (the numbering before the real module's), which the loader
    # migrates (tests/data/README.md).
    with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data",
                           "tmcm142_nvm_layout1.eeprom"), "rb") as f:
        write("eeprom_image", "tmcm-142_nvm_layout1", b"\1" + f.read())
    # Another module's valid image (TMCM-142 bytes as the TMCM-1636's file).
    with open(os.path.join(CORPUS, "eeprom_image", "tmcm-142_factory"), "rb") as f:
        write("eeprom_image", "tmcm-142_image_for_tmcm-1636", b"\0" + f.read()[1:])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--motwin", help="build/motwin, for the EEPROM seeds")
    args = parser.parse_args()
    tmcl_seeds()
    program_seeds()
    sdo_seeds()
    engine_seeds()
    can_text_seeds()
    text_file_seeds()
    tmcm142_board_seeds()
    eeprom_seeds(args.motwin and os.path.abspath(args.motwin))
    for target in sorted(os.listdir(CORPUS)):
        print(f"{target}: {len(os.listdir(os.path.join(CORPUS, target)))} seeds")
    return 0


if __name__ == "__main__":
    sys.exit(main())
