#!/usr/bin/env bash
# deps.sh - install what the project needs, and only what is missing:
# Debian packages (apt-get) and a Python virtual environment from the pinned
# requirements.txt. Safe to run again: it says what it does and skips what is there.
set -euo pipefail
cd "$(dirname "$0")/.."

VENV=${VENV:-build/venv}
PACKAGES=(
  gcc make libc6-dev          # host build
  libsdl2-dev                 # hal/sdl: the host window
  libpng-dev                  # host/png.c: the PNG files of build/render, emu, display, fltool
  zlib1g-dev                  # bspc's checksum of its blobs (tools/bspc/crc_fast.c)
  libcmocka-dev               # C unit tests
  gcc-arm-none-eabi           # Cortex-M build (firmware, no-float check)
  qemu-system-arm             # the Cortex-M3 board (mps2-an385) the firmware runs on in tests
  qemu-system-x86             # the PC (i386, VGA) the hal/pcvga kernel runs on in tests
  gcc-multilib                # gcc -m32 and its libgcc: the hal/pcvga kernel
  libglib2.0-dev pkg-config   # building the QEMU instruction-counting plugin
  libusb-1.0-0-dev            # host/flash: USB DFU
  umockdev gir1.2-umockdev-1.0 libumockdev-dev python3-gi  # an emulated USB DFU device for build/flash's tests
  freedoom                    # real maps: freedoom1.wad, freedoom2.wad
  chocolate-doom              # Doom's own renderer, for make compare-doom (tools/doomcompare.py)
  zdbsp glbsp                 # other BSP compilers, for make bench-bsp
  valgrind                    # instruction counts
  clang libclang-rt-14-dev    # libFuzzer harnesses with ASan and UBSan (make fuzz, tests/fuzz)
  clang-format                # make format, make format-check (.clang-format is written for version 14)
  xvfb xauth                  # a display for SDL tests on headless machines
  python3 python3-venv        # tests and tools
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "deps: installing Debian packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "deps: Debian packages present"
fi

PY=${PYTHON:-python3}
if [ ! -x "$VENV/bin/python" ]; then
  echo "deps: creating Python virtual environment in $VENV"
  "$PY" -m venv "$VENV"
fi
if ! cmp -s requirements.txt "$VENV/.requirements"; then
  echo "deps: installing pinned Python packages from requirements.txt"
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check -r requirements.txt
  cp requirements.txt "$VENV/.requirements"
else
  echo "deps: Python packages present ($VENV)"
fi
