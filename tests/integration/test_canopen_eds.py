#!/usr/bin/python3
"""`motwin eds` (CiA-306) against the live TMCM-3216: the file parses with configparser, lists every
object in exactly one of the object lists, each ARRAY/RECORD's SubNumber matches its sub-index
sections, [DeviceInfo] has the numeric fields python-canopen needs, and every readable default
(with $NODEID resolved) is what an SDO upload of the freshly started module returns; AccessType,
PDOMapping, LowLimit and HighLimit are what the module enforces.
"""

import configparser
import os
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import CanServer, SdoAborted, check, check_equal  # noqa: E402
from motwin_harness import TempDir, run_tests  # noqa: E402

NODE = 9


def load_eds(motwin, tmp, *extra):
    path = os.path.join(tmp, "tmcm-3216.eds")
    result = subprocess.run([motwin, "eds", "--module", "tmcm-3216", "-o", path, *extra], capture_output=True,
                            timeout=30)
    check_equal(result.returncode, 0, f"motwin eds exit status (stderr {result.stderr!r})")
    eds = configparser.ConfigParser(interpolation=None)
    eds.optionxform = str  # keys are case-sensitive in the EDS world
    eds.read(path, encoding="ascii")
    return eds


def listed_objects(eds):
    objects = []
    for section in ("MandatoryObjects", "OptionalObjects", "ManufacturerObjects"):
        count = int(eds[section]["SupportedObjects"])
        objects += [int(eds[section][str(i)], 16) for i in range(1, count + 1)]
    return objects


def test_eds_structure(motwin):
    with TempDir() as tmp:
        eds = load_eds(motwin, tmp, "--node-id", str(NODE))
        info = eds["DeviceInfo"]
        check_equal(int(info["VendorNumber"], 0), 0x286, "VendorNumber")
        check_equal(int(info["ProductNumber"], 0), 3216, "ProductNumber")
        for key in ("NrOfRXPDO", "NrOfTXPDO", "LSS_Supported", "BaudRate_1000", "Granularity"):
            int(info[key], 0)  # present and numeric (python-canopen cannot import empty numbers)
        check_equal(eds["DeviceComissioning"]["NodeID"], str(NODE), "NodeID")
        objects = listed_objects(eds)
        check_equal(len(objects), len(set(objects)), "objects listed once")
        check(0x1000 in objects and 0x1018 in objects and 0x1A83 in objects and 0x2705 in objects,
              "expected objects listed")
        for index in objects:
            section = f"{index:04X}"
            check(eds.has_section(section), f"section [{section}]")
            if int(eds[section]["ObjectType"], 0) in (8, 9):
                subs = [s for s in eds.sections() if s.startswith(section + "sub")]
                check_equal(int(eds[section]["SubNumber"]), len(subs), f"SubNumber of {section}")
        check_equal(eds["1008"]["DefaultValue"], "TMCM-3216", "1008 default")
        check_equal(eds["1800sub1"]["DefaultValue"], "$NODEID+0x180", "1800 sub 1 default")


def test_eds_defaults_match_the_live_module(motwin):
    with TempDir() as tmp:
        eds = load_eds(motwin, tmp)
        with CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE) as server, server.bus() as bus:
            checked = 0
            for section in eds.sections():
                entry = eds[section]
                if "DataType" not in entry or entry.get("AccessType") == "wo":
                    continue
                index = int(section[:4], 16)
                sub = int(section[7:], 16) if "sub" in section else 0
                default = entry["DefaultValue"]
                if int(entry["DataType"], 0) == 0x9:
                    check_equal(bus.upload(NODE, index, sub).decode("ascii"), default, f"{section} string")
                    checked += 1
                    continue
                if default.startswith("$NODEID+"):
                    expected = NODE + int(default[len("$NODEID+"):], 0)
                else:
                    expected = int(default, 0)
                if (index, sub) in ((0x1018, 4),):
                    continue  # serial number: given by the board
                value = bus.upload_u(NODE, index, sub)
                bits = {0x2: 8, 0x3: 16, 0x4: 32}.get(int(entry["DataType"], 0))
                if bits and value >= 1 << (bits - 1):  # INTEGER8/16/32: the EDS writes them signed
                    value -= 1 << bits
                check_equal(value, expected, f"{section} default")
                checked += 1
            check(checked > 200, f"only {checked} entries checked")
            server.stop()


SIZES = {0x1: 1, 0x2: 1, 0x3: 2, 0x4: 4, 0x5: 1, 0x6: 2, 0x7: 4}  # bytes of the numeric DataTypes


def numeric_entries(eds):
    """(section, index, sub, entry, size) of every numeric entry."""
    for section in eds.sections():
        entry = eds[section]
        if "DataType" not in entry or int(entry["DataType"], 0) not in SIZES:
            continue
        yield section, int(section[:4], 16), int(section[7:], 16) if "sub" in section else 0, entry, \
            SIZES[int(entry["DataType"], 0)]


def test_eds_access_limits_and_mapping(motwin):
    """AccessType, PDOMapping, LowLimit and HighLimit: a few entries by value, then every entry
    against the live module (a value just outside each limit, every entry mapped into a TPDO and
    an RPDO of axis 1, a write to every ro/const entry)."""
    with TempDir() as tmp:
        eds = load_eds(motwin, tmp)
        expected = {  # section: (AccessType, PDOMapping, LowLimit, HighLimit)
            "1000": ("const", "0", None, None),
            "1001": ("ro", "0", None, None),
            "1800sub2": ("rw", "0", None, None),  # 1..240, 254, 255: refused by value (06090030), not by range
            "1A00sub0": ("rw", "0", None, "0x3"),
            "1A00sub1": ("rw", "0", None, None),
            "1029sub1": ("rw", "0", None, "0x2"),
            "2704": ("rw", "0", "0x14", "0x3E8"),
            "2705": ("rw", "0", "0x1", None),
            "6040": ("rw", "1", None, None),
            "6041": ("ro", "1", None, None),
            "6840": ("rw", "1", None, None),
            "6065": ("rw", "0", None, "0x7FFFFFFF"),  # following error window
        }
        for section, (access, mapping, low, high) in expected.items():
            entry = eds[section]
            check_equal((entry["AccessType"], entry["PDOMapping"], entry.get("LowLimit"), entry.get("HighLimit")),
                        (access, mapping, low, high), f"[{section}] AccessType, PDOMapping, LowLimit, HighLimit")

        with CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE) as server, server.bus() as bus:
            limits = read_only = 0
            mapped = {0x1A40: [], 0x1640: []}
            for section, index, sub, entry, size in numeric_entries(eds):
                if entry["AccessType"] not in ("rw", "wo"):
                    continue
                for key, delta, code in (("LowLimit", -1, 0x06090032), ("HighLimit", 1, 0x06090031)):
                    if key in entry:
                        value = (int(entry[key], 0) + delta) & ((1 << (8 * size)) - 1)
                        check_equal(bus.abort_code(bus.download, NODE, index, sub, value, size), code,
                                    f"[{section}] {key} {entry[key]} {delta:+d}")
                        limits += 1
            # Axis 1's TPDO 1 and RPDO 1 are not valid at power-up: their mappings may be changed.
            bus.download(NODE, 0x1A40, 0, 0, 1)
            bus.download(NODE, 0x1640, 0, 0, 1)
            for section, index, sub, entry, size in numeric_entries(eds):
                for mapping_index, direction_ok in ((0x1A40, True), (0x1640, entry["AccessType"] in ("rw", "wo"))):
                    mappable = entry["PDOMapping"] == "1" and direction_ok
                    try:
                        bus.download(NODE, mapping_index, 1, index << 16 | sub << 8 | 8 * size, 4)
                        code = 0
                    except SdoAborted as aborted:
                        code = aborted.code
                    check_equal(code, 0 if mappable else 0x06040041, f"[{section}] mapped by {mapping_index:04X}")
                    if mappable:
                        mapped[mapping_index].append(section)
                if entry["AccessType"] in ("ro", "const"):
                    check_equal(bus.abort_code(bus.download, NODE, index, sub, 0, size), 0x06010002,
                                f"[{section}] {entry['AccessType']}: write")
                    read_only += 1
            axis_0 = ["6040", "6041", "6060", "6061", "6062", "6063", "6064", "606C", "607A", "6081", "6083", "6084",
                      "60B0", "60B1", "60FD", "60FF"]
            check_equal([s for s in mapped[0x1A40] if s[0] != "7" and s[:2] != "68"], ["2702", "2703sub1", "270Esub1", "270Esub2"] + axis_0,
                        "TPDO-mappable entries of the module (I/O) and of axis 0")
            check_equal(len(mapped[0x1A40]), 4 + 3 * 16, "TPDO-mappable entries")
            check_equal([s for s in mapped[0x1640] if s[0] != "7" and s[:2] != "68"],
                        ["2703sub1", "6040", "6060", "607A", "6081", "6083", "6084", "60B0", "60B1", "60FF"],
                        "RPDO-mappable entries of the module and of axis 0 (the rw ones)")
            check_equal(len(mapped[0x1640]), 1 + 3 * 9, "RPDO-mappable entries")
            check(limits > 150 and read_only > 100, f"{limits} limits and {read_only} ro/const entries checked")
            server.stop()


def test_eds_refuses_modules_without_canopen(motwin):
    result = subprocess.run([motwin, "eds", "--module", "tmcm-1636"], capture_output=True, timeout=30)
    check_equal(result.returncode, 2, "exit status")
    check(b"no CANopen object dictionary" in result.stderr, f"stderr {result.stderr!r}")


if __name__ == "__main__":
    run_tests([test_eds_structure, test_eds_defaults_match_the_live_module, test_eds_access_limits_and_mapping,
               test_eds_refuses_modules_without_canopen])
