#!/usr/bin/python3
"""Writes the seed corpora in fuzz/corpus/<target>/ from the inputs the tests use.

Run from anywhere: `fuzz/make_seeds.py [--motwin build/motwin]`. With --motwin, the EEPROM seeds
start from the factory image a real `motwin serve` writes; without it they are kept as they are.
The seeds are committed; libFuzzer adds what it finds to a copy (scripts/fuzz.sh).
"""

import argparse
import os
import random
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


def write(target, name, data):
    directory = os.path.join(CORPUS, target)
    os.makedirs(directory, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(directory, name), "wb") as f:
        f.write(data)


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


def sdo_seeds():
    # FuzzedDataProvider input: any bytes; these give the provider varied integers.
    rng = random.Random(3216)
    for n in (16, 64, 256, 1024):
        for target in ("canopen_sdo", "tmcl_engine", "canopen_pdo", "canopen_lss", "tmcl_can_frames"):
            write(target, f"random_{n}", bytes(rng.randrange(256) for _ in range(n)))


def engine_seeds():
    # The ramp, homing, TMCM-3216 drive and TMCM-142 engine targets read FuzzedDataProvider input
    # too; their own generator, so that the seeds of the targets above stay as they are.
    rng = random.Random(402)
    for n in (64, 256, 1024, 4096):
        for target in ("eight_point_ramp", "cia402_homing", "tmcm3216_drive", "tmcm142_engine"):
            for k in range(2):
                write(target, f"random_{n}_{k}", bytes(rng.randrange(256) for _ in range(n)))
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
    slcan = [
        "\r\r\rS8\rO\rt6018400010000000000\rV\rN\rF\rC\r",
        "S4\rO\rT000006012AABB\rr6010\rR000001230\rZ1\rC\r",
        "O\rL\rt601\rt60190011223344556677889\r" + "t" * 70 + "\rC\rs0314\r",
        "O\rt0000\rt7FF812345678ABCDEF01\r\n\0C\r",
    ]
    for i, text in enumerate(slcan):
        write("slcan_stream", f"session_{i}", bytes([1 + i * 5]) + text.encode())


def text_file_seeds():
    write("scenario_file", "example",
          "# supply dip while the home switch closes\n\n2.0   VSUPPLY 26.5   # after the dip\n0.5\tGPI0 1\n"
          "   1e-3 ref_h 1\r\n0.5 GPI0 0\n")
    write("scenario_file", "motor_signals", "0 LOAD_TORQUE 0.2\n0.1 TEMP 80\n0.2 AI0 5\n1e9 GPI3 1\n")
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
    if not motwin:
        return
    with tempfile.TemporaryDirectory() as tmp:
        proc = subprocess.Popen([motwin, "serve", "--module", "tmcm-1636", "--state-dir", tmp, "--tmcl-tcp",
                                 "127.0.0.1:0"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
        for line in proc.stdout:
            if line.strip() == b"ready":
                break
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=15)
        with open(os.path.join(tmp, "tmcm-1636.eeprom"), "rb") as f:
            good = f.read()
    write("eeprom_image", "factory", good)
    flipped = bytearray(good)
    flipped[64 + 43 * 4] ^= 0xFF
    write("eeprom_image", "payload_flipped", bytes(flipped))
    write("eeprom_image", "truncated", good[:len(good) // 2])
    write("eeprom_image", "header_only", good[:64])
    # Valid header CRC over a payload with another size: gets past the first checks.
    header = bytearray(good[:64])
    struct.pack_into("<I", header, 52, 16)
    struct.pack_into("<I", header, 60, zlib.crc32(bytes(header[:60])) & 0xFFFFFFFF)
    write("eeprom_image", "other_payload_size", bytes(header) + good[64:80])


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
