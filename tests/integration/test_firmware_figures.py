#!/usr/bin/python3
"""bench/firmware_figures.py, the firmware images' figures (docs/firmware.md, "Per-tick
figures"), works: its qemu plugin loads and counts the instructions of each control tick, at rest
and while moving, and the painted stack is read back.

- both images: a window at rest and one while moving of the requested number of ticks; at rest a
  non-zero count below what qemu's -icount shift=0 gives a tick (50,000 instructions, or the
  image would fall behind its own ticks), the count while moving above it (the ramp generator
  runs), min <= mean <= max;
- the stack's high-water mark above nothing and below the stack region (the paint was found);
- flash and RAM from the image's sections;
- the profile (--profile): per window, the functions' instructions add up to the window's mean
  (the plugin counts the same blocks twice, once per address), the tick function is in both
  windows and the motion code only in the moving one costs more than at rest.
The figures themselves are not asserted (bench/ reports them).

Skipped, visibly (exit status 77), as integration/test_firmware_qemu.py is: qemu-system-arm not
installed, or the ARM toolchain not installed and so no image built; also without a host C
compiler for the plugin.
"""

import json
import os
import shutil
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from motwin_harness import Skipped, TestFailure, check, check_equal, run_tests  # noqa: E402

SOURCE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FIRMWARE_DIR = os.environ.get("MOTWIN_FIRMWARE_DIR", os.path.join(SOURCE_DIR, "build-cortex-m"))
TOOL = os.path.join(SOURCE_DIR, "bench", "firmware_figures.py")
SKIP_STATUS = 77
TICKS = 200
TICK_BUDGET_INSTRUCTIONS = 50_000  # 50 us at one instruction per ns (-icount shift=0)


def test_figures_of_both_images(motwin):
    del motwin  # the images are measured, not the host binary
    for name in ("tmcm1636", "tmcm142"):
        if (shutil.which("qemu-system-arm") and shutil.which("arm-none-eabi-g++")
                and not os.path.exists(os.path.join(FIRMWARE_DIR, f"{name}.elf"))):
            raise TestFailure(f"{FIRMWARE_DIR}/{name}.elf is missing: run scripts/build-firmware.sh")
    result = subprocess.run([sys.executable, TOOL, "--json", "--profile", "5", "--ticks", str(TICKS),
                             "--firmware-dir", FIRMWARE_DIR],
                            capture_output=True, text=True, timeout=500)
    if result.returncode == SKIP_STATUS:
        raise Skipped(result.stdout.strip())
    check_equal(result.returncode, 0, f"{TOOL}: {result.stdout} {result.stderr}")
    figures = json.loads(result.stdout)
    check_equal([image["module"] for image in figures], ["TMCM-1636", "TMCM-142"], "images measured")
    for image in figures:
        what = image["module"]
        rest, moving = image["rest"], image["moving"]
        for window in (rest, moving):
            check_equal(window["ticks"], TICKS, f"{what}: ticks in a window")
            check(0 < window["min"] <= window["mean"] <= window["max"], f"{what}: min <= mean <= max in {window}")
            check(window["max"] < TICK_BUDGET_INSTRUCTIONS, f"{what}: a tick within the board's 50 us: {window}")
        check(rest["mean"] < moving["mean"], f"{what}: at rest {rest['mean']} not below moving {moving['mean']}")
        check(0 < image["stack_used"] < image["stack_used"] + image["stack_free"],
              f"{what}: stack high-water mark {image['stack_used']} of {image['stack_used'] + image['stack_free']}")
        check(image["stack_free"] >= 8192, f"{what}: less than the linker script's 8 KiB of stack left")
        check(image["text"] > 10_000 and image["bss"] > 10_000, f"{what}: sections {image}")
        for window, profile in ((rest, image["profile_rest"]), (moving, image["profile_moving"])):
            total = sum(profile.values())
            # One translation block at each end of the window may fall on either side.
            check(abs(total - window["mean"]) <= 0.01 * window["mean"],
                  f"{what}: the profile's {total:.1f} instructions per tick against the window's {window['mean']}")
            check(profile.get("void motwin::firmware::mps2_an386::run_control_tick", 0) > 0,
                  f"{what}: run_control_tick not in the profile {sorted(profile)[:20]}")
        motion = [function for function in image["profile_moving"] if "motion::" in function]
        check(motion, f"{what}: no motion:: function while moving")
        check(sum(image["profile_moving"][f] for f in motion) > sum(image["profile_rest"].get(f, 0) for f in motion),
              f"{what}: the motion code costs no more while moving")


if __name__ == "__main__":
    run_tests([test_figures_of_both_images])
