#!/usr/bin/env bash
# Builds Motwin and starts a virtual TMCM-1636 on simulated hardware.
# Extra arguments go to `motwin serve` (see `build/motwin serve --help`).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build --target motwin
exec build/motwin serve --module tmcm-1636 "$@"
