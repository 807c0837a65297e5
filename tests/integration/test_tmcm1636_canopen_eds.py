#!/usr/bin/python3
"""`motwin eds --module tmcm-1636 --firmware canopen` against Trinamic's EDS of the TMCM-1636
CANopen firmware 1.12 (tests/data/TMCM-1636-CANopen_Hw1.1_Fw1.12.eds), both read as plain INI
files: every object and sub-index of Trinamic's is in Motwin's with the same ParameterName,
ObjectType, SubNumber, DataType, AccessType, PDOMapping and (where Trinamic's gives one)
DefaultValue, compared as numbers ($NODEID+ forms, hexadecimal two's complement of signed types);
Motwin's has nothing Trinamic's lacks; [DeviceInfo] and [DummyUsage] agree. The only allowed
differences are the rows of the table under "## Differences from the published EDS" in
docs/tmcm-1636-canopen.md, each of which must be a real difference with the values it gives.
Last, the names PyTrinamic's examples look up through python-canopen resolve in Motwin's EDS
as they do in Trinamic's.
"""

import configparser
import os
import re
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from motwin_harness import TempDir, TestFailure, check, check_equal, run_tests  # noqa: E402

SOURCE_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
TRINAMIC_EDS = os.path.join(SOURCE_DIR, "tests", "data", "TMCM-1636-CANopen_Hw1.1_Fw1.12.eds")
DIFFERENCES_DOC = os.path.join(SOURCE_DIR, "docs", "tmcm-1636-canopen.md")
DIFFERENCES_HEADING = "## Differences from the published EDS"
NODE_ID = 1  # for $NODEID+ defaults: both files use the same form, any node ID compares them

# CiA-306 DataTypes: (bits, signed) of the numeric ones.
NUMERIC_TYPES = {0x1: (1, False), 0x2: (8, True), 0x3: (16, True), 0x4: (32, True), 0x5: (8, False),
                 0x6: (16, False), 0x7: (32, False), 0x15: (64, True), 0x1B: (64, False)}
ACCESS_NAMES = ("ro", "wo", "rw", "rwr", "rww", "const")
# The fields a row of the docs' table may name, and the EDS key each stands for.
DIFFERENCE_FIELDS = {"access": "AccessType", "default": "DefaultValue", "name": "ParameterName",
                     "type": "DataType", "mapping": "PDOMapping"}
DEVICE_INFO_KEYS = ("VendorNumber", "ProductNumber", "RevisionNumber", "NrOfRXPDO", "NrOfTXPDO", "LSS_Supported")


def read_ini(path):
    eds = configparser.ConfigParser(interpolation=None, strict=True)
    eds.optionxform = str  # keys are case-sensitive in the EDS world
    with open(path, encoding="latin-1") as f:
        eds.read_file(f)
    return eds


def motwin_eds(motwin, tmp):
    path = os.path.join(tmp, "tmcm-1636-canopen.eds")
    result = subprocess.run([motwin, "eds", "--module", "tmcm-1636", "--firmware", "canopen", "-o", path],
                            capture_output=True, timeout=30)
    check_equal(result.returncode, 0, f"motwin eds exit status (stderr {result.stderr!r})")
    return read_ini(path)


def entries(eds):
    """{(index, sub): section} of every object and sub-index: sub None for the object's own
    section ([2041]), a number for [2041sub1] (case of 'sub' and hex digits as CiA-306 allows)."""
    found = {}
    for name in eds.sections():
        m = re.fullmatch(r"([0-9A-Fa-f]{4})(?:[sS][uU][bB]([0-9A-Fa-f]{1,2}))?", name)
        if m:
            key = (int(m.group(1), 16), int(m.group(2), 16) if m.group(2) else None)
            check(key not in found, f"two sections for {key}")
            found[key] = eds[name]
    return found


def where(key):
    index, sub = key
    return f"{index:04X}" if sub is None else f"{index:04X} sub {sub}"


def number(text):
    return int(text.strip(), 0)


def default_value(section):
    """A numeric DefaultValue as (value, relative to the node ID): hexadecimal of a signed type
    is its two's complement (0x80000000 of an INTEGER32 is -2^31)."""
    text = section["DefaultValue"].strip()
    plus_node_id = text.upper().startswith("$NODEID")
    if plus_node_id:
        text = text[len("$NODEID"):].lstrip("+").strip() or "0"
    value = int(text, 0)
    bits, signed = NUMERIC_TYPES.get(number(section["DataType"]), (0, False))
    if signed and text.lower().startswith("0x") and value >= 1 << (bits - 1):
        value -= 1 << bits
    return value, plus_node_id


def field_value(section, key):
    """What a field means, for comparison: numbers as numbers, access and names as text."""
    if key not in section:
        return None
    if key in ("ObjectType", "DataType", "PDOMapping", "SubNumber"):
        return number(section[key])
    if key == "DefaultValue":
        if "DataType" in section and number(section["DataType"]) in NUMERIC_TYPES:
            return default_value(section)
        return section[key]
    return section[key].strip()


def doc_value(key, text):
    """A value as the docs' table writes it, in field_value()'s terms."""
    if key == "DefaultValue":
        return text
    if key in ("DataType", "PDOMapping"):
        return number(text)
    return text


def read_differences():
    """The rows `| object | sub | field | Motwin | EDS | why |` of the table under the heading."""
    with open(DIFFERENCES_DOC, encoding="utf-8") as f:
        lines = f.read().splitlines()
    check(DIFFERENCES_HEADING in lines, f"docs/tmcm-1636-canopen.md has no heading {DIFFERENCES_HEADING!r}")
    rows = []
    header_seen = False
    for line in lines[lines.index(DIFFERENCES_HEADING) + 1:]:
        if line.startswith("## "):
            break
        if not line.startswith("|"):
            if rows:
                break  # the end of the table
            continue
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if not header_seen:
            check_equal([c.lower() for c in cells[:5]], ["object", "sub", "field", "motwin", "eds"], "table header")
            header_seen = True
            continue
        if set("".join(cells)) <= set("-: "):
            continue  # the separator line
        check(len(cells) == 6 and all(cells), f"a row of the differences table with six cells: {line!r}")
        check(cells[2] in DIFFERENCE_FIELDS, f"field {cells[2]!r} of {line!r} (one of {sorted(DIFFERENCE_FIELDS)})")
        rows.append({"key": (int(cells[0], 16), int(cells[1], 0)), "field": DIFFERENCE_FIELDS[cells[2]],
                     "motwin": cells[3], "eds": cells[4], "line": line})
    check(rows, "the differences table has no rows")
    return rows


def lookup(eds_entries, key):
    """The section of (index, sub): sub 0 of a VAR is its own section."""
    index, sub = key
    if (index, sub) in eds_entries:
        return eds_entries[(index, sub)]
    if sub == 0 and (index, None) in eds_entries and number(eds_entries[(index, None)]["ObjectType"]) == 7:
        return eds_entries[(index, None)]
    return None


def resolve_default(section, value_text):
    """A table cell of the default column as field_value() gives it for `section`."""
    if number(section["DataType"]) in NUMERIC_TYPES:
        probe = {"DataType": section["DataType"], "DefaultValue": value_text}
        return default_value(probe)
    return value_text


def test_every_object_of_trinamics_eds_is_in_motwins_as_it_declares_it(motwin):
    trinamic = entries(read_ini(TRINAMIC_EDS))
    differences = read_differences()
    allowed = {(row["key"], row["field"]) for row in differences}
    with TempDir() as tmp:
        motwin_entries = entries(motwin_eds(motwin, tmp))
    check(len(trinamic) > 250, f"only {len(trinamic)} sections read from Trinamic's EDS")
    missing = [where(key) for key in trinamic if key not in motwin_entries]
    check_equal(missing, [], "objects and sub-indices of Trinamic's EDS missing from Motwin's")
    extra = [where(key) for key in motwin_entries if key not in trinamic]
    check_equal(extra, [], "objects and sub-indices in Motwin's EDS that Trinamic's lacks")
    mismatches = []
    compared = 0
    for key, theirs in trinamic.items():
        ours = motwin_entries[key]
        variable_key = (key[0], 0) if key[1] is None else key  # how the docs' table names a VAR
        for field in ("ParameterName", "ObjectType", "SubNumber", "DataType", "AccessType", "PDOMapping",
                      "DefaultValue"):
            if field not in theirs:
                continue  # Motwin may give a default where Trinamic's gives none (docs: decisions)
            if (variable_key, field) in allowed and (key[1] is not None or number(theirs["ObjectType"]) == 7):
                continue
            expected, actual = field_value(theirs, field), field_value(ours, field)
            compared += 1
            if expected != actual:
                mismatches.append(f"{where(key)} {theirs['ParameterName']}: {field} Trinamic {theirs[field]!r}, "
                                  f"Motwin {ours.get(field)!r}")
    check_equal(mismatches, [], "differences from Trinamic's EDS that docs/tmcm-1636-canopen.md does not list")
    check(compared > 1200, f"only {compared} fields compared")


def test_every_listed_difference_is_real_with_the_values_the_docs_give(motwin):
    trinamic = entries(read_ini(TRINAMIC_EDS))
    with TempDir() as tmp:
        motwin_entries = entries(motwin_eds(motwin, tmp))
    stale, wrong = [], []
    rows = read_differences()
    check_equal(len({(row["key"], row["field"]) for row in rows}), len(rows), "rows listed once")
    for row in rows:
        theirs, ours = lookup(trinamic, row["key"]), lookup(motwin_entries, row["key"])
        check(theirs is not None and ours is not None, f"{row['line']}: no such entry in both EDS files")
        field = row["field"]
        check(field in theirs and field in ours, f"{row['line']}: {field} missing in one of the EDS files")
        if field == "DefaultValue":
            documented_ours = resolve_default(ours, row["motwin"])
            documented_theirs = resolve_default(theirs, row["eds"])
        else:
            documented_ours, documented_theirs = doc_value(field, row["motwin"]), doc_value(field, row["eds"])
        actual_ours, actual_theirs = field_value(ours, field), field_value(theirs, field)
        if actual_ours == actual_theirs:
            stale.append(row["line"])
        if (actual_ours, actual_theirs) != (documented_ours, documented_theirs):
            wrong.append(f"{row['line']}: Motwin {ours[field]!r}, Trinamic {theirs[field]!r}")
    check(not stale and not wrong, f"rows of the differences table that are no longer differences: {stale}; "
                                   f"rows whose values are not the files': {wrong}")


def test_device_info_and_dummy_usage_agree(motwin):
    trinamic = read_ini(TRINAMIC_EDS)
    with TempDir() as tmp:
        ours = motwin_eds(motwin, tmp)
    theirs_info, ours_info = trinamic["DeviceInfo"], ours["DeviceInfo"]
    keys = list(DEVICE_INFO_KEYS) + [k for k in theirs_info if k.startswith("BaudRate_")]
    check_equal(sorted(k for k in ours_info if k.startswith("BaudRate_")),
                sorted(k for k in theirs_info if k.startswith("BaudRate_")), "BaudRate_ keys")
    for key in keys:
        check(key in ours_info, f"[DeviceInfo] {key} missing from Motwin's EDS")
        check_equal(number(ours_info[key]), number(theirs_info[key]), f"[DeviceInfo] {key}")
    check_equal({k: number(v) for k, v in ours["DummyUsage"].items()},
                {k: number(v) for k, v in trinamic["DummyUsage"].items()}, "[DummyUsage]")
    # The object lists name exactly the objects of the sections.
    for eds, who in ((ours, "Motwin's"), (trinamic, "Trinamic's")):
        listed = set()
        for section in ("MandatoryObjects", "OptionalObjects", "ManufacturerObjects"):
            count = number(eds[section]["SupportedObjects"])
            listed |= {number(eds[section][str(i)]) for i in range(1, count + 1)}
        check_equal(listed, {index for index, sub in entries(eds) if sub is None}, f"{who} object lists")


# The names PyTrinamic's TMCM-1636 CANopen examples look up (research 4.1): objects, and records
# with the sub-indices used, as python-canopen resolves them (exact ParameterName).
NAMED_OBJECTS = ("Commutation Mode", "Controlword", "Statusword", "Profile Acceleration", "Profile Velocity in pp-mode",
                 "Position Scaler", "Position Window", "Position Window Time", "Modes of Operation",
                 "Target Velocity", "Velocity Actual Value")
NAMED_SUBS = {"ADC Configuration": ("ADC_I0_Raw", "ADC_I0_Offset", "ADC_I1_Raw", "ADC_I1_Offset"),
              "ABN Encoder Settings": ("Direction", "Steps")}
# What the names stand for in the scripts.
NAMED_INDICES = {"Commutation Mode": 0x2055, "Controlword": 0x6040, "Statusword": 0x6041,
                 "Profile Acceleration": 0x6083, "Profile Velocity in pp-mode": 0x6081, "Position Scaler": 0x2058,
                 "Position Window": 0x6067, "Position Window Time": 0x6068, "Modes of Operation": 0x6060,
                 "Target Velocity": 0x60FF, "Velocity Actual Value": 0x606C, "ADC Configuration": 0x2060,
                 "ABN Encoder Settings": 0x2080}
NAMED_SUB_INDICES = {("ADC Configuration", "ADC_I0_Raw"): 1, ("ADC Configuration", "ADC_I1_Raw"): 2,
                     ("ADC Configuration", "ADC_I0_Offset"): 3, ("ADC Configuration", "ADC_I1_Offset"): 4,
                     ("ABN Encoder Settings", "Direction"): 1, ("ABN Encoder Settings", "Steps"): 2}


def resolve(eds_entries, name, sub_name=None):
    """python-canopen's od[name] / od[name][sub_name]: the index (and sub-index) whose
    ParameterName is exactly the name; KeyError (here a failure) when none is."""
    objects = [index for (index, sub), section in eds_entries.items()
               if sub is None and section["ParameterName"] == name]
    check(len(objects) == 1, f"{name!r} names {len(objects)} objects")
    if sub_name is None:
        return objects[0]
    subs = [sub for (index, sub), section in eds_entries.items()
            if index == objects[0] and sub is not None and section["ParameterName"] == sub_name]
    check(len(subs) == 1, f"{name!r}[{sub_name!r}] names {len(subs)} sub-indices")
    return objects[0], subs[0]


def test_names_the_examples_look_up_resolve(motwin):
    trinamic = entries(read_ini(TRINAMIC_EDS))
    with TempDir() as tmp:
        ours = entries(motwin_eds(motwin, tmp))
    for eds, who in ((ours, "Motwin's EDS"), (trinamic, "Trinamic's EDS")):
        try:
            for name in NAMED_OBJECTS:
                check_equal(resolve(eds, name), NAMED_INDICES[name], f"{name!r}")
            for name, sub_names in NAMED_SUBS.items():
                for sub_name in sub_names:
                    check_equal(resolve(eds, name, sub_name),
                                (NAMED_INDICES[name], NAMED_SUB_INDICES[(name, sub_name)]), f"{name!r}[{sub_name!r}]")
        except TestFailure as failure:
            raise TestFailure(f"{who}: {failure}") from None
    # The numbers the legacy scripts bind (module.sdo[0x2702] and so on) exist too; the
    # comparison above covers them. 'Motor Status Flags' (the uncalled get_motor_status_flags())
    # is the firmware 1.09 EDS's name of 2101; firmware 1.12's, and Motwin's, is 'Status Flags'.
    for eds in (ours, trinamic):
        check_equal(eds[(0x2101, None)]["ParameterName"], "Status Flags", "2101")


if __name__ == "__main__":
    run_tests([test_every_object_of_trinamics_eds_is_in_motwins_as_it_declares_it,
               test_every_listed_difference_is_real_with_the_values_the_docs_give,
               test_device_info_and_dummy_usage_agree, test_names_the_examples_look_up_resolve])
