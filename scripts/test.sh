#!/usr/bin/env bash
# Builds Motwin twice (optimised, and with AddressSanitizer + UndefinedBehaviorSanitizer) and
# the Cortex-M firmware images (scripts/build-firmware.sh), and runs every test in both builds:
# unit tests, the freestanding-core check and the integration tests against real peers
# (python3-serial, sockets, pseudo-terminals, the firmware under qemu-system-arm); then a bounded
# fuzz run of every libFuzzer target (fuzz/README.md).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build -j"$jobs"
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DMOTWIN_SANITIZE=ON -DMOTWIN_BENCH=OFF >/dev/null
cmake --build build-asan -j"$jobs"
# The firmware images the qemu test boots (tests/integration/test_firmware_qemu.py).
MOTWIN_JOBS=$jobs scripts/build-firmware.sh

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
status=0
echo "== tests (optimised build) =="
ctest --test-dir build -j"$jobs" --output-on-failure || status=1
echo "== tests (ASan + UBSan build) =="
ctest --test-dir build-asan -j"$jobs" --output-on-failure || status=1
echo "== fuzz smoke (libFuzzer + ASan + UBSan, clang, build-fuzz/; scripts/fuzz.sh) =="
scripts/fuzz.sh --smoke || status=1
exit $status
