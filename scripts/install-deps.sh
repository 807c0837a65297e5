#!/usr/bin/env bash
# Installs what Motwin needs, only what is missing: Debian 12 packages (apt-get) and the web
# console's front-end packages (npm ci in web/, pinned by web/package-lock.json).
set -euo pipefail
cd "$(dirname "$0")/.."
packages=(
  build-essential cmake ninja-build pkg-config
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev libfmt-dev nlohmann-json3-dev
  libwebsockets-dev libuv1-dev
  python3 python3-serial python3-can python3-websocket socat
  chromium chromium-driver python3-selenium
  ccache clang tshark valgrind
  # The firmware images (scripts/build-firmware.sh, docs/firmware.md): the ARM cross compiler with
  # newlib nano and the C++ headers (the C++ library itself is not linked), and the emulator.
  gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-dev qemu-system-arm
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# Node.js with npm installs the web packages; Debian's own when the machine has none (a Node.js
# from elsewhere brings its npm, and conflicts with Debian's npm package).
if ! command -v npm >/dev/null; then missing+=(nodejs npm); fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
if [ "${#missing[@]}" -gt 0 ]; then
  echo "motwin: installing missing Debian packages: ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
# npm ci when the installed tree is missing or older than the lockfile.
if [ ! -f web/node_modules/.package-lock.json ] || [ web/package-lock.json -nt web/node_modules/.package-lock.json ]; then
  echo "motwin: installing the web console's npm packages (npm ci in web/)" >&2
  (cd web && npm ci --no-audit --no-fund --loglevel=error)
fi
