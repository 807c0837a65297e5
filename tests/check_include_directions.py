#!/usr/bin/python3
"""Fails when a file under src/ includes across the allowed direction of the layers.

Usage: check_include_directions.py SRC_DIR

The rules (docs/architecture.md, "Include directions"):

  types/   includes nothing of the project (leaf vocabulary headers, standard library only)
  board/   includes only board/ and types/
  core/    includes only core/, board/ and types/
  sim/     includes no host/, tools/ or cli/; of a module's core folder only its hardware units
           (core/modules/<module>/*_hardware.h), not the module profile: the simulated board
           models the hardware, not the firmware
  host/    includes no tools/ or cli/
  tools/   includes no cli/
  cli/     may include every layer but firmware/; nothing below it includes cli/
  firmware/ (the Cortex-M images: board layer and start-up) includes only firmware/, core/,
           board/ and types/; no other layer includes it

and a module's folder in any layer (src/<layer>/modules/<module>/) includes no other module's
folder: modules meet only in src/host/module_registry.cpp, which is not in a module folder.

An include names a project file when its first path component is a layer folder
("core/canopen/pdo.h"), or when it resolves relative to the including file's folder. Every
violation is printed as `path:line: ...` (path relative to SRC_DIR's parent); the exit status is
1 when there is one, 0 otherwise. Standard library only.
"""

import os
import re
import sys

LAYERS = ("types", "board", "core", "sim", "host", "tools", "cli", "firmware")

# Layer -> the layers it may include (a layer not listed may not be included).
ALLOWED = {
    "types": set(),
    "board": {"board", "types"},
    "core": {"core", "board", "types"},
    "sim": {"sim", "core", "board", "types"},
    "host": {"host", "sim", "core", "board", "types"},
    "tools": {"tools", "host", "sim", "core", "board", "types"},
    "cli": set(LAYERS) - {"firmware"},
    "firmware": {"firmware", "core", "board", "types"},
}

SOURCE_SUFFIXES = (".h", ".hpp", ".hh", ".inl", ".ipp", ".cpp", ".cc", ".cxx")
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')


def module_of(parts):
    """The module a src-relative path belongs to ("tmcm1636" for core/modules/tmcm1636/x.h)."""
    if len(parts) >= 4 and parts[1] == "modules":
        return parts[2]
    return None


def resolve(include, including_dir, src_dir):
    """The src-relative path components of a project include, or None for anything else."""
    parts = include.split("/")
    if parts[0] in LAYERS:
        return parts
    candidate = os.path.normpath(os.path.join(including_dir, include))
    if os.path.isfile(candidate):
        relative = os.path.relpath(candidate, src_dir)
        if not relative.startswith(".."):
            parts = relative.split(os.sep)
            if parts[0] in LAYERS:
                return parts
    return None


def check_file(path, src_dir):
    """Violations of one file, as (line number, message)."""
    parts = os.path.relpath(path, src_dir).split(os.sep)
    layer = parts[0]
    module = module_of(parts)
    violations = []
    with open(path, encoding="utf-8", errors="replace") as source:
        for number, line in enumerate(source, start=1):
            match = INCLUDE.match(line)
            if match is None:
                continue
            included = resolve(match.group(2), os.path.dirname(path), src_dir)
            if included is None:
                continue
            target_layer = included[0]
            shown = "/".join(included)
            if target_layer not in ALLOWED[layer]:
                allowed = ", ".join(sorted(ALLOWED[layer])) or "nothing of the project"
                violations.append(
                    (number, f'{layer}/ includes "{shown}" ({target_layer}/): {layer}/ may include {allowed}'))
                continue
            if layer == "sim" and target_layer == "core" and len(included) >= 4 and included[1] == "modules" \
                    and not included[-1].endswith("_hardware.h"):
                violations.append(
                    (number, f'sim/ includes "{shown}": of core/modules/ the simulation includes only '
                             "*_hardware.h units (the hardware, not the firmware)"))
                continue
            target_module = module_of(included)
            if module is not None and target_module is not None and target_module != module:
                violations.append(
                    (number, f'module {module} includes "{shown}" of module {target_module}: '
                             "modules meet only in src/host/module_registry.cpp"))
    return violations


def check_tree(src_dir):
    """Every violation under src_dir, as (path, line number, message), and the number of files."""
    src_dir = os.path.abspath(src_dir)
    found = []
    files = 0
    for root, dirs, names in os.walk(src_dir):
        dirs.sort()
        relative_root = os.path.relpath(root, src_dir)
        if relative_root == ".":
            # Only the layer folders are checked; anything else at the top is not a layer.
            dirs[:] = [d for d in dirs if d in LAYERS]
            continue
        for name in sorted(names):
            if not name.endswith(SOURCE_SUFFIXES):
                continue
            path = os.path.join(root, name)
            files += 1
            for number, message in check_file(path, src_dir):
                found.append((path, number, message))
    return found, files


def main(argv):
    if len(argv) != 2 or not os.path.isdir(argv[1]):
        print("usage: check_include_directions.py SRC_DIR", file=sys.stderr)
        return 2
    src_dir = os.path.abspath(argv[1])
    shown_base = os.path.dirname(src_dir)
    violations, files = check_tree(src_dir)
    for path, number, message in violations:
        print(f"{os.path.relpath(path, shown_base)}:{number}: {message}")
    if violations:
        print(f"{len(violations)} include(s) cross the allowed direction (docs/architecture.md, "
              f"\"Include directions\")")
        return 1
    print(f"{files} files checked: every include follows the allowed directions")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
