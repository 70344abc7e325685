#!/usr/bin/env bash
# Fetches Debian's amd64 kernel for the QEMU framebuffer test and unpacks what the test boots:
# the uncompressed vmlinux (PVH boot) and the bochs DRM modules. The package is downloaded with
# `apt-get download` and unpacked with dpkg-deb; it is never installed.
#
# Usage: tests/qemu-fbdev/fetch_kernel.sh [CACHE_DIR]
#   CACHE_DIR defaults to $MASKLINE_QEMU_CACHE, else /var/cache/maskline/qemu-linux when writable,
#   else build/qemu-linux. Safe to run again: does nothing when the current kernel is unpacked.
# Result: CACHE_DIR/current -> CACHE_DIR/<version>/ holding vmlinux, modules/*.ko
# and VERSION. Exit status non-zero, with one line on stderr, when it cannot.
set -eu

say() { echo "qemu-linux: $*"; }
die() { echo "qemu-linux: $*" >&2; exit 1; }

default_cache() {
  if [ -n "${MASKLINE_QEMU_CACHE:-}" ]; then echo "$MASKLINE_QEMU_CACHE"; return; fi
  if mkdir -p /var/cache/maskline/qemu-linux 2>/dev/null && [ -w /var/cache/maskline/qemu-linux ]; then
    echo /var/cache/maskline/qemu-linux
  else
    echo "$PWD/build/qemu-linux"
  fi
}
cache=${1:-$(default_cache)}
mkdir -p "$cache" || die "cannot create $cache"
cache=$(cd "$cache" && pwd)

# Several worktrees may share the cache: one fetch at a time.
exec 9>"$cache/.lock"
flock 9

# DRM drivers with fbdev emulation for QEMU's display adapters and the modules they need:
# bochs (-vga std, 32 bpp): drm drm_kms_helper ttm drm_ttm_helper drm_vram_helper bochs
# cirrus (-vga cirrus, 16 or 24 bpp): drm drm_kms_helper drm_shmem_helper cirrus
# cirrusfb (-vga cirrus, the legacy fbdev driver: virtual screens and hardware panning)
modules=(drm drm_kms_helper ttm drm_ttm_helper drm_vram_helper bochs drm_shmem_helper cirrus cirrusfb)

kernel_version() {
  apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ { sub(/^linux-image-/, "", $2); print $2; exit }'
}

ver=$(kernel_version || true)
if [ -z "$ver" ]; then
  say "apt knows no linux-image-amd64 yet: running apt-get update"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq || true
  ver=$(kernel_version || true)
fi
if [ -z "$ver" ]; then
  # Offline: keep using a kernel fetched earlier.
  if complete "$cache/current"; then
    say "apt cannot name the current kernel; using the cached $(cat "$cache/current/VERSION")"
    exit 0
  fi
  die "cannot find the kernel version (apt-cache depends linux-image-amd64 gave nothing)"
fi

dest="$cache/$ver"
complete() {
  [ -f "$1/VERSION" ] && [ -f "$1/vmlinux" ] || return 1
  for m in "${modules[@]}"; do [ -f "$1/modules/$m.ko" ] || return 1; done
}
if complete "$dest"; then
  ln -sfn "$ver" "$cache/current"
  say "kernel $ver already unpacked in $dest"
  exit 0
fi

work=$(mktemp -d "$cache/.fetch.XXXXXX")
trap 'rm -rf "$work"' EXIT
say "downloading linux-image-$ver (about 67 MiB) into $cache"
# apt-get download runs as the unprivileged _apt user where it can; a world-writable work dir keeps it
# from complaining.
chmod 0777 "$work"
(cd "$work" && apt-get download -q "linux-image-$ver" >/dev/null 2>"$work/apt.err") ||
  die "apt-get download linux-image-$ver failed: $(tail -n 1 "$work/apt.err")"
deb=$(ls "$work"/linux-image-*.deb 2>/dev/null | head -n 1)
[ -n "$deb" ] || die "apt-get download left no .deb"

say "unpacking the kernel image and ${#modules[@]} display driver modules (dpkg-deb, not installed)"
mkdir -p "$work/x"
dpkg-deb -x "$deb" "$work/x" || die "dpkg-deb -x $deb failed"
bz="$work/x/boot/vmlinuz-$ver"
[ -f "$bz" ] || die "the package has no /boot/vmlinuz-$ver"

mkdir -p "$work/out/modules"
# The uncompressed vmlinux (an ELF with a PVH note) boots directly and about 3x faster than the
# bzImage. Find the compressed payload inside the bzImage and decompress it (as the kernel's
# scripts/extract-vmlinux does).
extract() {
  local magic=$1 cmd=$2 off
  for off in $(LC_ALL=C grep -obUaP "$magic" "$bz" | cut -d: -f1); do
    tail -c +$((off + 1)) "$bz" | $cmd >"$work/vmlinux.try" 2>/dev/null || true
    if [ "$(head -c 4 "$work/vmlinux.try" | od -An -tx1 | tr -d ' ')" = 7f454c46 ]; then
      mv "$work/vmlinux.try" "$work/out/vmlinux"
      return 0
    fi
  done
  return 1
}
extract '\xFD\x37\x7A\x58\x5A\x00' 'xz -dc' ||
  extract '\x28\xB5\x2F\xFD' 'zstd -dc' ||
  extract '\x1F\x8B\x08' 'gzip -dc' ||
  die "cannot find an ELF vmlinux inside $bz"

moddir="$work/x/lib/modules/$ver/kernel"
for m in "${modules[@]}"; do
  f=$(find "$moddir" -name "$m.ko" -o -name "$m.ko.xz" -o -name "$m.ko.zst" | head -n 1)
  [ -n "$f" ] || die "the package has no module $m"
  case "$f" in
    *.xz) xz -dc "$f" >"$work/out/modules/$m.ko" ;;
    *.zst) zstd -qdc "$f" >"$work/out/modules/$m.ko" ;;
    *) cp "$f" "$work/out/modules/$m.ko" ;;
  esac
done
echo "$ver" >"$work/out/VERSION"

rm -rf "$dest"
mv "$work/out" "$dest"
ln -sfn "$ver" "$cache/current"
# Older kernels of earlier security updates are no longer needed.
for old in "$cache"/*/; do
  old=${old%/}
  case "$(basename "$old")" in "$ver" | current) ;; *) rm -rf "$old" ;; esac
done
say "kernel $ver ready in $dest ($(du -sh "$dest" | cut -f1))"
