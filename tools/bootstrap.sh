#!/usr/bin/env bash
# Installs, with apt, the Debian packages that maskline's build, tests and demo need and that are missing.
# Safe to run again: it installs nothing when everything is present. Prints what it installs.
# Also fetches Debian's kernel for the QEMU framebuffer test (tests/qemu-fbdev/fetch_kernel.sh).
set -eu

packages=(
  g++ make pkg-config
  libgtest-dev          # unit and property tests
  libtinygltf-dev       # scene compiler (glTF 2.0 reader)
  nlohmann-json3-dev    # tinygltf's JSON parser
  libstb-dev            # tinygltf's image decoder
  libpng-dev            # PNG sink
  libgpiod-dev          # SPI panel reset/data-command lines
  assimp-testmodels     # real glTF 2.0 inputs, good and broken
  assimp-utils          # converts the COLLADA duck to glTF for the benchmarks and the texture tests
  valgrind              # instruction counts for benchmarks
  time                  # peak resident memory in the benchmarks
  clang                 # libFuzzer target for the blob reader
  zlib1g-dev            # static CLI build for the QEMU framebuffer test (libpng needs zlib)
  gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib  # Cortex-M builds of src/
  qemu-system-arm       # Cortex-M boards
  qemu-system-x86 busybox-static cpio  # a real Linux /dev/fb0 under QEMU
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "bootstrap: all ${#packages[@]} packages present"
else
  echo "bootstrap: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  echo "bootstrap: installed ${#missing[@]} package(s)"
fi

# Debian's kernel for the QEMU framebuffer test: downloaded and unpacked into a cache, not installed.
# Not fatal here: without it the test fails and says why.
bash "$(dirname "$0")/../tests/qemu-fbdev/fetch_kernel.sh" ||
  echo "bootstrap: no kernel for the QEMU framebuffer test (tests/qemu-fbdev/fetch_kernel.sh failed)"
