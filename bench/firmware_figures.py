#!/usr/bin/env python3
"""The firmware images' figures (docs/firmware.md, "Per-tick figures"): for each module image in
build-cortex-m/, flash and RAM from the linked image, the stack's high-water mark, and the guest
instructions per control tick at rest and while moving, counted by qemu, with the load they
would put on a 72 MHz and a 168 MHz Cortex-M4.

    bench/firmware_figures.py                    # build-cortex-m/, both images, a markdown table
    bench/firmware_figures.py --ticks 500 tmcm1636
    bench/firmware_figures.py --json            # the figures as JSON (tests/integration/test_firmware_figures.py)
    bench/firmware_figures.py --profile 15      # also where the ticks' instructions go: the 15 costliest functions

qemu runs each image with `-icount shift=0,sleep=off` (one instruction per nanosecond of the
board's time, so the counts do not depend on the host's load) and the plugin
bench/firmware/qemu_tick_count.c, compiled here with the host's C compiler. The plugin counts the
instructions from one entry of run_control_tick (firmware/mps2_an386/tmcl_main_loop.h) to the
next: the tick and everything else the core runs in that period (interrupts, the main loop). A
window of --ticks ticks starts --skip ticks after the last byte received, so no TMCL command is
in it: at rest after a GAP, and while moving after an MVP to a target far away (checked: the
axis still moves afterwards and has not reached it). The start-up code paints the free stack
(firmware/mps2_an386/startup.cpp); the monitor's pmemsave reads it back at the end.

Exit status 77 (and a message) when qemu-system-arm, the ARM toolchain, a C compiler or the
images are missing: nothing was measured.
"""
import argparse
import bisect
import json
import os
import re
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import time

SOURCE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PLUGIN_SOURCE = os.path.join(SOURCE_DIR, "bench", "firmware", "qemu_tick_count.c")
sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.join(SOURCE_DIR, "bench", "firmware"))
from qemu_mps2 import QEMU, monitor_command, qemu_command  # noqa: E402
SKIP_STATUS = 77
STACK_PAINT = 0x5AC3A55C  # kStackPaint of firmware/mps2_an386/startup.cpp
TICK_US = 50
CLOCKS_MHZ = (72, 168)
TIMEOUT_S = 300.0

GAP, MVP, STAP, GET_VERSION = 6, 4, 7, 136
STATUS_OK = 100
# Per module: the target of the MVP (far beyond what a window reaches), the axis parameters that
# say it is still moving (actual speed) and has not arrived (position reached), and one stored
# with STAP (an EEPROM write, for the stack's high-water mark).
MODULES = {
    "tmcm1636": {"title": "TMCM-1636", "target": 100_000_000, "speed": 42, "reached": 55, "stored": 43},
    "tmcm142": {"title": "TMCM-142", "target": 100_000_000, "speed": 3, "reached": 8, "stored": 4},
}


class Skip(Exception):
    pass


def frame(command, type_, bank, value):
    body = struct.pack(">BBBBi", 1, command, type_, bank, value)
    return body + bytes([sum(body) & 0xFF])


class Board:
    """qemu with one image, UART0 and the monitor on Unix sockets in a temporary directory."""

    def __init__(self, image, plugin, tick_address, mark_address, ticks, skip, directory, profile=False):
        self.directory = directory
        self.windows_path = os.path.join(directory, "windows.txt")
        self.profile_path = os.path.join(directory, "profile.txt")
        serial_path = os.path.join(directory, "uart0.sock")
        self.monitor_path = os.path.join(directory, "monitor.sock")
        plugin_arg = (f"{plugin},tick={tick_address:#x},mark={mark_address:#x},skip={skip},ticks={ticks},"
                      f"out={self.windows_path}" + (f",profile={self.profile_path}" if profile else ""))
        self.log = open(os.path.join(directory, "qemu.log"), "wb")
        self.process = subprocess.Popen(
            qemu_command(image, self.monitor_path, f"unix:{serial_path},server=on,wait=off",
                         "-icount", "shift=0,sleep=off", "-plugin", plugin_arg),
            cwd=directory, stdin=subprocess.DEVNULL, stdout=self.log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + TIMEOUT_S
        while True:
            try:
                self.serial = socket.socket(socket.AF_UNIX)
                self.serial.connect(serial_path)
                break
            except OSError:
                self.serial.close()
                if self.process.poll() is not None or time.monotonic() > deadline:
                    self.process.kill()
                    self.process.wait()
                    self.log.close()
                    raise RuntimeError(f"qemu did not start: {self.qemu_log()}")
                time.sleep(0.02)

    def qemu_log(self):
        with open(os.path.join(self.directory, "qemu.log"), encoding="utf-8", errors="replace") as log:
            return log.read().strip()

    def close(self):
        self.serial.close()
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait()
        self.log.close()

    def request(self, command, type_, bank=0, value=0, timeout=TIMEOUT_S):
        """One TMCL request; returns (status, value). Retried while the image starts."""
        deadline = time.monotonic() + timeout
        while True:
            self.serial.sendall(frame(command, type_, bank, value))
            reply = b""
            self.serial.settimeout(1.0)
            try:
                while len(reply) < 9:
                    more = self.serial.recv(9 - len(reply))
                    if not more:
                        raise RuntimeError("qemu closed the serial socket")
                    reply += more
            except socket.timeout:
                if time.monotonic() > deadline:
                    raise RuntimeError(f"no reply to command {command}")
                time.sleep(0.01)  # longer than the frame decoder's resync pause in the board's time
                continue
            if sum(reply[:8]) & 0xFF != reply[8] or reply[3] != command:
                raise RuntimeError(f"bad reply {reply.hex()} to command {command}")
            return reply[2], struct.unpack(">i", reply[4:8])[0]

    def wait_for_window(self, count):
        deadline = time.monotonic() + TIMEOUT_S
        while time.monotonic() < deadline:
            if os.path.exists(self.windows_path):
                with open(self.windows_path) as f:
                    lines = f.read().splitlines()
                if len(lines) >= count:
                    m = re.match(r"window ticks (\d+) min (\d+) mean ([\d.]+) max (\d+)", lines[count - 1])
                    return {"ticks": int(m.group(1)), "min": int(m.group(2)), "mean": float(m.group(3)),
                            "max": int(m.group(4))}
            if self.process.poll() is not None:
                raise RuntimeError(f"qemu stopped: {self.qemu_log()}")
            time.sleep(0.05)
        raise RuntimeError("the plugin measured no window (is it loaded? qemu -plugin)")

    def monitor(self, command):
        return monitor_command(self.monitor_path, command)


def symbols(image):
    output = subprocess.run(["arm-none-eabi-nm", "-C", image], capture_output=True, text=True, check=True).stdout
    found = {}
    for line in output.splitlines():
        parts = line.split(None, 2)
        if len(parts) == 3:
            name = parts[2]
            if name.startswith("void motwin::firmware::mps2_an386::run_control_tick<"):
                name = "run_control_tick"
            found[name] = int(parts[0], 16)
    for name in ("run_control_tick", "Uart0Rx_Handler", "_ebss", "_estack"):
        if name not in found:
            raise RuntimeError(f"{image} has no symbol {name}")
    return found


def functions(image):
    """(start address, end address, name) of every function in the image, sorted."""
    output = subprocess.run(["arm-none-eabi-nm", "-C", "-S", "--defined-only", image], capture_output=True,
                            text=True, check=True).stdout
    found = []
    for line in output.splitlines():
        parts = line.split(None, 3)
        if len(parts) == 4 and parts[2] in "tTwW":
            start = int(parts[0], 16) & ~1  # Thumb bit
            found.append((start, start + int(parts[1], 16), parts[3]))
    return sorted(found)


# Double-precision arithmetic, which a Cortex-M4F (single-precision FPU) runs in software:
# libgcc's routines and newlib's libm functions of double.
SOFT_DOUBLE = re.compile(r"^__(aeabi_(d\w+|[ilu]+2d|f2d)|\w*df[23]|\w*df[sd]i|float\w*df|fix\w*df\w*|extendsfdf2|truncdfsf2)$"
                         r"|^(__ieee754_\w+|__kernel_\w+|sqrt|floor|ceil|round|lround|llround|trunc|fmod|sin|cos|tan|exp|"
                         r"log|pow|atan2?|fabs)$")


def short_name(name):
    """A demangled name without its parameter list and template arguments (a readable row)."""
    depth, out = 0, []
    name = name.replace("(anonymous namespace)", "{anonymous}")
    for char in name.split("(")[0]:
        if char == "<":
            depth += 1
        elif char == ">":
            depth -= 1
        elif depth == 0:
            out.append(char)
    return "".join(out).strip() or name


def read_profile(path, image, ticks):
    """Per window of the plugin's profile file: {function: instructions per tick} and
    {function: calls per tick} (executions of the block at the function's first address)."""
    table = functions(image)
    starts = [start for start, _, _ in table]
    windows = []
    with open(path) as f:
        for line in f:
            if line.startswith("window"):
                windows.append(({}, {}))
                continue
            address, instructions, executions = (int(field, 0) for field in line.split())
            i = bisect.bisect_right(starts, address) - 1
            name = short_name(table[i][2]) if i >= 0 and address < table[i][1] else f"{address:#x}"
            per_tick, calls = windows[-1]
            per_tick[name] = per_tick.get(name, 0) + instructions / ticks
            if i >= 0 and address == table[i][0]:
                calls[name] = calls.get(name, 0) + executions / ticks
    return windows


def section_sizes(image):
    output = subprocess.run(["arm-none-eabi-size", "-A", image], capture_output=True, text=True, check=True).stdout
    sizes = {}
    for line in output.splitlines():
        m = re.match(r"^(\.\S+)\s+(\d+)\s+\d+", line)
        if m:
            sizes[m.group(1)] = int(m.group(2))
    return sizes


def measure(name, image, plugin, ticks, skip, profile=False):
    spec = MODULES[name]
    found = symbols(image)
    sizes = section_sizes(image)
    result = {"module": spec["title"], "text": sizes.get(".text", 0) + sizes.get(".ARM.exidx", 0),
              "data": sizes.get(".data", 0), "bss": sizes.get(".bss", 0)}
    with tempfile.TemporaryDirectory(prefix="motwin-fw-") as directory:
        board = Board(image, plugin, found["run_control_tick"], found["Uart0Rx_Handler"], ticks, skip, directory,
                      profile)
        try:
            board.request(GET_VERSION, 1)  # answers once started
            result["rest"] = board.wait_for_window(1)
            status, _ = board.request(MVP, 0, 0, spec["target"])
            if status != STATUS_OK:
                raise RuntimeError(f"MVP ABS {spec['target']}: status {status}")
            result["moving"] = board.wait_for_window(2)
            _, speed = board.request(GAP, spec["speed"])
            _, reached = board.request(GAP, spec["reached"])
            if speed == 0 or reached != 0:
                raise RuntimeError(f"the axis was not moving through the window: GAP {spec['speed']} = {speed}, "
                                   f"GAP {spec['reached']} = {reached}")
            status, _ = board.request(STAP, spec["stored"])
            if status != STATUS_OK:
                raise RuntimeError(f"STAP {spec['stored']}: status {status}")
            stack_bottom, stack_top = found["_ebss"], found["_estack"]
            # A relative file name (in qemu's working directory): the monitor parses '/' as a division.
            board.monitor(f"pmemsave {stack_bottom:#x} {stack_top - stack_bottom} stack.bin")
            with open(os.path.join(directory, "stack.bin"), "rb") as f:
                stack = f.read()
            if profile:
                windows = read_profile(board.profile_path, image, ticks)
                result["profile_rest"], result["calls_rest"] = windows[0]
                result["profile_moving"], result["calls_moving"] = windows[1]
        finally:
            board.close()
    words = struct.unpack(f"<{len(stack) // 4}I", stack[: len(stack) // 4 * 4])
    untouched = next((i for i, word in enumerate(words) if word != STACK_PAINT), len(words))
    result["stack_used"] = stack_top - (stack_bottom + 4 * untouched)
    result["stack_free"] = 4 * untouched
    return result


def load(instructions, mhz):
    return 100.0 * instructions / (mhz * TICK_US)


def markdown(results, ticks):
    lines = [f"Guest instructions per 50 us control tick under `qemu-system-arm -M mps2-an386 -icount shift=0`, "
             f"windows of {ticks} ticks without a received byte; load = instructions / cycles per tick "
             f"({', '.join(f'{TICK_US * mhz} at {mhz} MHz' for mhz in CLOCKS_MHZ)}), a lower bound: a Cortex-M4 "
             "takes more than one cycle per instruction on average (loads, branches, flash wait states).", "",
             "| image | flash: text + data | RAM: data + bss | stack high-water mark | instructions per tick at rest "
             "(min / mean / max) | while moving (min / mean / max) | "
             + " | ".join(f"load at {mhz} MHz, moving (mean / max)" for mhz in CLOCKS_MHZ) + " |",
             "|---|---|---|---|---|---|" + "---|" * len(CLOCKS_MHZ)]
    for r in results:
        rest, moving = r["rest"], r["moving"]
        loads = " | ".join(f"{load(moving['mean'], mhz):.1f} % / {load(moving['max'], mhz):.1f} %"
                           for mhz in CLOCKS_MHZ)
        lines.append(f"| {r['module']} | {r['text']:,} + {r['data']:,} B | {r['data']:,} + {r['bss']:,} B | "
                     f"{r['stack_used']:,} B (of {r['stack_used'] + r['stack_free']:,}) | "
                     f"{rest['min']:,} / {rest['mean']:,.0f} / {rest['max']:,} | "
                     f"{moving['min']:,} / {moving['mean']:,.0f} / {moving['max']:,} | {loads} |")
    return "\n".join(lines)


def profile_markdown(results, rows):
    """Per image: the functions that cost most of a moving tick, own instructions (not their callees')."""
    lines = ["Where the instructions of a tick go: each function's own instructions (its callees count for "
             "themselves) per tick, in the same windows, by qemu's translation blocks mapped to the image's "
             "symbols.", ""]
    for r in results:
        moving, rest = r["profile_moving"], r["profile_rest"]
        total = sum(moving.values())
        soft = sum(v for k, v in moving.items() if SOFT_DOUBLE.match(k))
        lines += [f"**{r['module']}**: {total:,.0f} instructions per moving tick, of which {soft:,.0f} "
                  f"({100 * soft / total:.0f} %) in software double-precision arithmetic (libgcc's `__*df*` and "
                  "`__aeabi_d*` routines, libm's functions of `double`).", "",
                  "| function | own instructions per tick moving | share | calls per tick moving | "
                  "own instructions per tick at rest | calls per tick at rest |",
                  "|---|---|---|---|---|---|"]
        for function, per_tick in sorted(moving.items(), key=lambda kv: -kv[1])[:rows]:
            lines.append(f"| `{function}` | {per_tick:,.0f} | {100 * per_tick / total:.1f} % | "
                         f"{r['calls_moving'].get(function, 0):,.1f} | {rest.get(function, 0):,.0f} | "
                         f"{r['calls_rest'].get(function, 0):,.1f} |")
        lines.append("")
    return "\n".join(lines)


def build_plugin(directory):
    compiler = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")
    if compiler is None:
        raise Skip("no C compiler for the qemu plugin (cc)")
    os.makedirs(directory, exist_ok=True)
    plugin = os.path.join(directory, "libqemu_tick_count.so")
    subprocess.run([compiler, "-O2", "-Wall", "-Wextra", "-shared", "-fPIC", "-o", plugin, PLUGIN_SOURCE], check=True)
    return plugin


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("modules", nargs="*", help=f"images to measure (default: {', '.join(MODULES)})")
    parser.add_argument("--firmware-dir", default=os.path.join(SOURCE_DIR, "build-cortex-m"))
    parser.add_argument("--ticks", type=int, default=2000, help="ticks per window (default 2000 = 100 ms)")
    parser.add_argument("--skip", type=int, default=40, help="ticks after the last received byte (default 40)")
    parser.add_argument("--json", action="store_true", help="the figures as JSON instead of a table")
    parser.add_argument("--json-file", help="also write the figures as JSON to this file")
    parser.add_argument("--profile", type=int, metavar="ROWS", default=0,
                        help="also the ROWS functions with the most instructions per moving tick")
    args = parser.parse_args()
    for name in args.modules:
        if name not in MODULES:
            parser.error(f"unknown image {name!r} (one of {', '.join(MODULES)})")
    args.modules = args.modules or list(MODULES)
    try:
        if shutil.which(QEMU) is None:
            raise Skip(f"{QEMU} not installed (Debian: qemu-system-arm; scripts/install-deps.sh)")
        if shutil.which("arm-none-eabi-nm") is None:
            raise Skip("the ARM toolchain is not installed, so no firmware image was built "
                       "(Debian: gcc-arm-none-eabi; scripts/install-deps.sh)")
        images = {name: os.path.join(args.firmware_dir, f"{name}.elf") for name in args.modules}
        missing = [image for image in images.values() if not os.path.exists(image)]
        if missing:
            raise Skip(f"no firmware image {', '.join(missing)}: run scripts/build-firmware.sh")
        plugin = build_plugin(os.path.join(args.firmware_dir, "qemu-plugin"))
    except Skip as reason:
        print(f"firmware figures skipped: {reason}")
        return SKIP_STATUS
    results = [measure(name, image, plugin, args.ticks, args.skip, args.profile > 0)
               for name, image in images.items()]
    if args.json_file:
        with open(args.json_file, "w") as f:
            json.dump(results, f, indent=1)
    if args.json:
        print(json.dumps(results, indent=1))
    else:
        print(markdown(results, args.ticks))
        if args.profile:
            print()
            print(profile_markdown(results, args.profile))
    return 0


if __name__ == "__main__":
    sys.exit(main())
