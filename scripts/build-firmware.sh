#!/usr/bin/env bash
# Builds the Cortex-M firmware images in build-cortex-m/ (docs/firmware.md): the core compiled by
# arm-none-eabi-g++ for a Cortex-M4F, on the MPS2 AN386 board that qemu-system-arm emulates.
# Exits 0 with a message, building nothing, when the ARM toolchain is not installed.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v arm-none-eabi-g++ >/dev/null; then
  echo "motwin: arm-none-eabi-g++ not found (Debian: gcc-arm-none-eabi, libnewlib-arm-none-eabi," \
       "libstdc++-arm-none-eabi-dev; scripts/install-deps.sh): firmware images not built" >&2
  exit 0
fi
jobs=${MOTWIN_JOBS:-$(nproc 2>/dev/null || echo 2)}
cmake -S . -B build-cortex-m -G Ninja -DCMAKE_BUILD_TYPE=MinSizeRel -DMOTWIN_FIRMWARE=ON \
      -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi-cortex-m4f.cmake >/dev/null
cmake --build build-cortex-m -j"$jobs"
