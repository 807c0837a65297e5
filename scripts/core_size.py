#!/usr/bin/python3
"""What the bytes of the core are: the text of libmotwin_core's object files (as `size` counts it:
code, constant data and the unwind tables) per module and per service, from binutils' readelf.

  scripts/core_size.py build-minsize            # markdown tables on stdout
  scripts/core_size.py build-minsize --symbols 30   # and the 30 biggest symbols
  scripts/core_size.py build-minsize --image build-minsize/core_all_modules.map
      # and what of it a firmware image of the three modules keeps (the core_all_modules target)
  scripts/core_size.py build --check build/libmotwin_core.a
      # the tables account for every byte: their sums equal `size -t` of the archive (CTest)

scripts/bench.sh runs it on its -Os build (build-minsize/), so the performance report carries the
tables; docs/PERFORMANCE.md "How to read it" explains them. Every byte lands in exactly one row, so
each table's total is the archive's `size -t` total.
"""
import collections
import os
import re
import subprocess
import sys

MODULES = ("tmcm142", "tmcm1636", "tmcm3216")
KINDS = ("code", "constants", "unwind")

# Service of a source file, by its path under src/core/ (first match wins).
FILE_SERVICES = [
    (r"tmcl/engine\.cpp", "TMCL engine (dispatch, commands)"),
    (r"tmcl/(interpreter|program_memory)\.cpp", "TMCL stored programs (interpreter, program memory)"),
    (r"tmcl/ramdebug\.cpp", "TMCL RAMDebug"),
    (r"tmcl/ascii_link\.cpp", "TMCL ASCII interface"),
    (r"tmcl/(serial|can)_link\.cpp", "TMCL links (serial frames, TMCL over CAN)"),
    (r"canopen/sdo_(server|block)\.cpp", "CANopen SDO server (expedited, segmented, block)"),
    (r"canopen/pdo\.cpp", "CANopen PDO"),
    (r"canopen/(nmt|heartbeat_consumer)\.cpp", "CANopen NMT, heartbeat"),
    (r"canopen/emergency\.cpp", "CANopen EMCY"),
    (r"canopen/sync\.cpp", "CANopen SYNC"),
    (r"canopen/lss_slave\.cpp", "CANopen LSS"),
    (r"canopen/storage\.cpp", "CANopen storage (1010/1011)"),
    (r"canopen/object_dictionary\.cpp", "CANopen object dictionary (lookup)"),
    (r"canopen/node\.cpp", "CANopen node (services wired, restarts, communication errors)"),
    (r"canopen/node_guarding\.cpp", "CANopen NMT, heartbeat"),
    (r"cia402/", "CiA-402 drive (state machine, modes, homing)"),
    (r"motion/(trapezoid_ramp|s_ramp|eight_point_ramp)\.cpp", "motion ramps (trapezoid, S, eight-point)"),
    (r"motion/(pi_regulator|easy_pid)\.cpp", "motion regulators (PI, easy PID)"),
    (r"motion/", "motion other (hall, coolStep, stall, reference search)"),
    (r"modules/tmcm3216/tmcm3216_objects\.cpp", "TMCM-3216 object dictionary table (rows, bindings, names)"),
    (r"modules/tmcm3216/tmcm3216_stepper\.cpp", "stepper axis (TMCM-3216)"),
    (r"modules/tmcm3216/tmcm3216_emergencies\.cpp", "CANopen EMCY"),
    (r"modules/tmcm3216/tmcm3216\.cpp", "module (TMCM-3216: node application, axes)"),
    (r"modules/tmcm142/tmcm142_parameters\.cpp", "TMCL parameter tables (rows, bindings, names)"),
    (r"modules/tmcm1636/tmcm1636_parameters\.cpp", "TMCL parameter tables (rows, bindings, names)"),
    (r"modules/tmcm142/tmcm142_axis\.cpp", "stepper axis (TMCM-142)"),
    (r"modules/tmcm1636/tmcm1636_axis(_servo)?\.cpp", "BLDC servo axis (TMCM-1636: FOC, regulators, encoders)"),
    (r"modules/tmcm142/tmcm142\.cpp", "module (TMCM-142: TMCL module, storage)"),
    (r"modules/tmcm1636/tmcm1636\.cpp", "module (TMCM-1636: TMCL module, storage)"),
    (r"modules/tmcm1636/tmcm1636_canopen_objects\.cpp", "TMCM-1636 CANopen object dictionary table (rows, bindings, names)"),
    (r"modules/tmcm1636/tmcm1636_canopen\.cpp", "module (TMCM-1636 CANopen: node application, drive over the servo)"),
]

# Templates of shared services that a module's file instantiates count for the service (and still
# for the module), by the demangled name; lambdas of table bindings stay with their table.
SYMBOL_SERVICES = [
    (r"^motwin::cia402::", "CiA-402 drive (state machine, modes, homing)"),
    (r"^motwin::canopen::(TableDictionary|ObjectDictionary)", "CANopen object dictionary (lookup)"),
    (r"^motwin::canopen::ObjectStorage", "CANopen storage (1010/1011)"),
    (r"^motwin::canopen::(PdoService|Pdo)", "CANopen PDO"),
    (r"^motwin::canopen::SdoServer", "CANopen SDO server (expedited, segmented, block)"),
    (r"^motwin::tmcl::(ModuleStorage|NvmLayout)", "TMCL module storage (EEPROM image)"),
    (r"^motwin::tmcl::TmclInterpreter", "TMCL stored programs (interpreter, program memory)"),
    (r"^motwin::tmcl::(TmclModule|TmclEngine|TmclRuntime)", "TMCL engine (dispatch, commands)"),
    (r"^motwin::tmcl::(kMnemonicTable|mnemonic_data)", "TMCL ASCII interface"),
    (r"^motwin::motion::kQuarterSine", "motion other (hall, coolStep, stall, reference search)"),
]


def run(*args):
    return subprocess.run(args, capture_output=True, text=True, check=True).stdout


def demangle(names):
    if not names:
        return {}
    out = subprocess.run(["c++filt"], input="\n".join(names), capture_output=True, text=True, check=True).stdout
    return dict(zip(names, out.splitlines()))


class ObjectFile:
    """The allocated bytes of one object file, attributed to its symbols."""

    def __init__(self, path):
        self.path = path
        self.sections = {}  # index -> (name, type, size, flags)
        for line in run("readelf", "-SW", path).splitlines():
            m = re.match(r"\s*\[\s*(\d+)\]\s+(\S+)\s+(\S+)\s+\S+\s+\S+\s+([0-9a-f]+)\s+\S+\s+(\S*)\s", line)
            if m:
                self.sections[int(m.group(1))] = (m.group(2), m.group(3), int(m.group(4), 16), m.group(5))
        self.symbols = []  # (section index, value, size, name)
        for line in run("readelf", "-sW", path).splitlines():
            m = re.match(r"\s*\d+:\s+([0-9a-f]+)\s+(\d+)\s+(\S+)\s+\S+\s+\S+\s+(\d+)\s+(\S+)", line)
            if m and m.group(3) in ("FUNC", "OBJECT") and int(m.group(2)) > 0:
                self.symbols.append((int(m.group(4)), int(m.group(1), 16), int(m.group(2)), m.group(5)))

    def kind(self, index):
        name, typ, _, flags = self.sections[index]
        if "A" not in flags:
            return None
        if typ == "NOBITS":
            return "bss"
        if "W" in flags:
            return "data"
        if name.startswith(".eh_frame"):
            return "unwind"
        if "X" in flags:
            return "code"
        return "constants"

    def pieces(self):
        """(symbol or None, kind, bytes) covering every allocated byte of the file."""
        by_section = collections.defaultdict(list)
        for index, value, size, name in self.symbols:
            by_section[index].append((value, size, name))
        section_symbol = {}
        for index, value, size, name in self.symbols:
            section_symbol.setdefault((self.sections[index][0], value), name)
        for index, (name, _, size, _) in self.sections.items():
            kind = self.kind(index)
            if kind is None or size == 0:
                continue
            if kind == "unwind":
                yield from self.unwind_pieces(size, section_symbol)
                continue
            named = 0
            seen = set()
            for value, sym_size, sym in sorted(by_section.get(index, [])):
                if value in seen:  # aliases (constructors C1/C2) share their bytes
                    continue
                seen.add(value)
                named += sym_size
                yield sym, kind, sym_size
            if size > named:  # string literals, padding, unnamed tables
                yield None, kind, size - named

    def unwind_pieces(self, size, section_symbol):
        # Each FDE belongs to the function its initial location points at (the relocation 8 bytes
        # into the FDE); CIEs and the rest stay with the file.
        targets = {}
        relocations = run("readelf", "-rW", self.path)
        in_eh = False
        for line in relocations.splitlines():
            if line.startswith("Relocation section"):
                in_eh = "'.rela.eh_frame'" in line
                continue
            m = re.match(r"([0-9a-f]+)\s+[0-9a-f]+\s+\S+\s+[0-9a-f]+\s+(\S+)\s*\+\s*([0-9a-f]+)", line)
            if in_eh and m:
                targets[int(m.group(1), 16)] = (m.group(2), int(m.group(3), 16))
        attributed = 0
        for line in run("readelf", "--debug-dump=frames", self.path).splitlines():
            m = re.match(r"([0-9a-f]{8}) ([0-9a-f]+) [0-9a-f]+ FDE", line)
            if not m:
                continue
            offset, length = int(m.group(1), 16), int(m.group(2), 16) + 4
            target = targets.get(offset + 8)
            symbol = None
            if target:
                symbol = section_symbol.get(target, target[0] if not target[0].startswith(".") else None)
            attributed += length
            yield symbol, "unwind", length
        if size > attributed:
            yield None, "unwind", size - attributed


def image_pieces(map_path):
    """(path under src/core/ without .o, section name, kind, bytes) of each input section of the
    core that a --gc-sections link kept, from the linker's map file (core_all_modules.map)."""
    pieces = []
    with open(map_path) as f:
        lines = f.read().split("Linker script and memory map", 1)[-1].splitlines()
    pending = None
    for line in lines:
        one = re.match(r"^ (\.\S+)\s+0x[0-9a-f]+\s+0x([0-9a-f]+)\s+(\S+\.o)$", line)
        if one:
            found = (one.group(1), int(one.group(2), 16), one.group(3))
        elif pending:
            two = re.match(r"^\s+0x[0-9a-f]+\s+0x([0-9a-f]+)\s+(\S+\.o)$", line)
            found = (pending, int(two.group(1), 16), two.group(2)) if two else None
        else:
            found = None
        head = re.match(r"^ (\.\S+)$", line)
        pending = head.group(1) if head else None
        if not found or "/src/core/" not in found[2] or found[1] == 0:
            continue
        name, size, obj = found
        rel = obj.split("/src/core/", 1)[1][: -len(".o")]
        if name.startswith(".text"):
            kind = "code"
        elif name.startswith(".rodata"):
            kind = "constants"
        elif name.startswith(".eh_frame"):
            kind = "unwind"
        elif name.startswith(".bss") or name.startswith(".tbss"):
            kind = "bss"
        else:
            kind = "data"
        pieces.append((rel, name, kind, size))
    return pieces


def print_image(map_path):
    pieces = image_pieces(map_path)
    if not pieces:
        print(f"(no input section of the core in {map_path})")
        return
    per_module = collections.defaultdict(collections.Counter)
    for rel, _, kind, size in pieces:
        per_module[module_of(rel)][kind] += size
    total = collections.Counter()
    print("The core in a firmware image of all three modules (bench/size/core_all_modules.cpp: a section per "
          "function and table, linked with --gc-sections): what the modules reach, each template and table "
          "once.")
    print()
    print("| module | text | code | constants | data | bss |")
    print("|---|---|---|---|---|---|")
    for module in MODULES + ("shared",):
        c = per_module[module]
        total.update(c)
        print(f"| {module} | {c['code'] + c['constants'] + c['unwind']} | {c['code']} | {c['constants']} "
              f"| {c['data']} | {c['bss']} |")
    text_bytes = total["code"] + total["constants"] + total["unwind"]
    print(f"| **total** | **{text_bytes}** ({text_bytes / 1024:.1f} KiB) | {total['code']} | {total['constants']} "
          f"| {total['data']} | {total['bss']} |")


def module_of(rel):
    m = re.match(r"modules/(\w+)/", rel)
    return m.group(1) if m and m.group(1) in MODULES else "shared"


def service_of(rel, symbol_name):
    if symbol_name and "{lambda" not in symbol_name and "field_binding" not in symbol_name:
        for pattern, service in SYMBOL_SERVICES:
            if re.search(pattern, symbol_name):
                return service
    for pattern, service in FILE_SERVICES:
        if re.search(pattern, rel):
            return service
    return "other (" + rel + ")"


def main():
    args = sys.argv[1:]
    if not args:
        sys.exit(__doc__)
    build = args[0]
    top = int(args[args.index("--symbols") + 1]) if "--symbols" in args else 0
    image_map = args[args.index("--image") + 1] if "--image" in args else None
    check_archive = args[args.index("--check") + 1] if "--check" in args else None
    root = os.path.join(build, "CMakeFiles", "motwin_core.dir", "src", "core")
    # The archive's members: an object a deleted source left behind in an incremental build
    # directory is not part of the core.
    archive_path = check_archive or os.path.join(build, "libmotwin_core.a")
    members = set(run("ar", "t", archive_path).split()) if os.path.exists(archive_path) else None
    objects = []
    for directory, _, files in os.walk(root):
        for f in sorted(files):
            if f.endswith(".o") and (members is None or f in members):
                path = os.path.join(directory, f)
                objects.append((os.path.relpath(path, root)[: -len(".o")], ObjectFile(path)))
    if not objects:
        sys.exit(f"core_size: no object files of motwin_core under {root}")
    objects.sort()

    pieces = []  # (rel, mangled symbol or None, kind, bytes)
    for rel, obj in objects:
        pieces += [(rel, sym, kind, size) for sym, kind, size in obj.pieces()]
    names = demangle(sorted({sym for _, sym, _, _ in pieces if sym}))

    modules = collections.defaultdict(collections.Counter)
    services = collections.defaultdict(collections.Counter)
    symbols = collections.Counter()
    for rel, sym, kind, size in pieces:
        module = module_of(rel)
        modules[module][kind] += size
        if kind in KINDS:
            services[service_of(rel, names.get(sym))][module] += size
            services[service_of(rel, names.get(sym))][kind] += size
            symbols[(names.get(sym) or f"(strings and unnamed constants of {rel})", kind)] += size

    def text(counter):
        return sum(counter[k] for k in KINDS)

    if check_archive:
        # Every byte in exactly one row: the tables' totals are the archive's `size -t` totals.
        totals = re.search(r"^\s*(\d+)\s+(\d+)\s+(\d+)\s+\d+\s+\S+\s+\(TOTALS\)",
                           run("size", "-t", check_archive), re.M)
        archive = tuple(int(g) for g in totals.groups())
        summed = collections.Counter()
        for c in modules.values():
            summed.update(c)
        by_module = (text(summed), summed["data"], summed["bss"])
        by_service = sum(text(c) for c in services.values())
        if by_module != archive or by_service != archive[0]:
            sys.exit(f"core_size: text, data, bss per module {by_module}, text per service {by_service}; "
                     f"size -t of {check_archive}: {archive}")
        print(f"core_size: per module and per service sums equal size -t of {check_archive}: {archive}")
        return

    print("Text of the core per module: code, constants (tables, strings) and unwind tables (.eh_frame), "
          "as `size` counts them; `shared` is the protocol, profile and motion code every module links.")
    print()
    print("| module | text | code | constants | unwind tables | data | bss |")
    print("|---|---|---|---|---|---|---|")
    total = collections.Counter()
    for module in MODULES + ("shared",):
        c = modules[module]
        total.update(c)
        print(f"| {module} | {text(c)} | {c['code']} | {c['constants']} | {c['unwind']} | {c['data']} | {c['bss']} |")
    print(f"| **total** | **{text(total)}** ({text(total) / 1024:.1f} KiB) | {total['code']} | {total['constants']} "
          f"| {total['unwind']} | {total['data']} | {total['bss']} |")
    print()
    print("Text per service (bytes), by the module whose files hold it; templates of a shared service "
          "instantiated in a module's file count for the service.")
    print()
    # The default build has no unwind tables (CMakeLists.txt); a build with them shows their share.
    unwind = total["unwind"] > 0
    print("| service | " + " | ".join(MODULES) + " | shared | text |" + (" of it unwind tables |" if unwind else ""))
    print("|---|" + "---|" * (len(MODULES) + 2 + unwind))
    for service, c in sorted(services.items(), key=lambda item: -text(item[1])):
        cells = " | ".join(str(c[m]) if c[m] else "" for m in MODULES + ("shared",))
        print(f"| {service} | {cells} | {text(c)} |" + (f" {c['unwind']} |" if unwind else ""))
    if top:
        print()
        print(f"The {top} biggest symbols (code and constants; unwind tables apart):")
        print()
        print("| bytes | kind | symbol |")
        print("|---|---|---|")
        ranked = [(size, kind, name) for (name, kind), size in symbols.items() if kind != "unwind"]
        for size, kind, name in sorted(ranked, reverse=True)[:top]:
            shown = name if len(name) <= 110 else name[:107] + "..."
            print(f"| {size} | {kind} | `{shown.replace('|', '/')}` |")
    if image_map:
        print()
        print_image(image_map)


if __name__ == "__main__":
    main()
