#!/usr/bin/env bash
# The real-kernel framebuffer test: boots Debian's kernel under QEMU (TCG) with a busybox initramfs,
# a DRM driver with fbdev emulation and a static guest program that draws into /dev/fb0 through the
# fbdev sink; then takes QEMU's screendump and compares it on the host, pixel for pixel, with the
# expected picture. One boot per screen configuration (see `configs` below).
#
# Usage: tests/qemu-fbdev/run.sh BUILD [NAME...]
#   BUILD holds qemu-fbdev/fb_pattern and qemu-fbdev/fb_check (make builds them); NAMEs pick
#   configurations (default: all). The kernel comes from tests/qemu-fbdev/fetch_kernel.sh (run by
#   tools/bootstrap.sh); set MASKLINE_QEMU_CACHE to use another cache directory.
# Output: one line per check, "ok NAME: ..." or "not ok NAME: reason"; work files in
# BUILD/qemu-fbdev/run/NAME/. Exit status non-zero when any check failed.
set -u

build=${1:-build}
shift || true
here=$(cd "$(dirname "$0")" && pwd)
build=$(cd "$build" && pwd)
guest="$build/qemu-fbdev/fb_pattern"
check="$build/qemu-fbdev/fb_check"
cli="$build/qemu-fbdev/maskline"  # static CLI: runs in the guest and renders the host-side reference
boot_timeout=${MASKLINE_QEMU_TIMEOUT:-60}

# name | QEMU display adapter | kernel video= | modules in insmod order (module:param=value) |
# bpp expected | guest program options | CLI render options (when set, the guest runs
# `maskline show OPTIONS --display fb:/dev/fb0` instead of the pattern, and the check compares with
# `maskline render OPTIONS -o host.png` on the host)
# fb16-cirrusfb-pan: the legacy cirrusfb driver; the guest makes the virtual screen twice the visible
# height and pans to its bottom half first, so the picture shows only if the sink honours yoffset.
bochs="drm drm_kms_helper ttm drm_ttm_helper drm_vram_helper bochs"
cirrus="drm drm_kms_helper drm_shmem_helper cirrus"
configs=(
  "fb32-bochs|std|1024x768|$bochs|32|"
  "fb16-cirrus|cirrus|1024x768-16|$cirrus|16|"
  "fb24-cirrus|cirrus|800x600-24|$cirrus|24|"
  "fb16-cirrusfb-pan|cirrus|640x480|cirrusfb:mode_option=640x480-16|16|--pan"
  "cli-fb16|cirrus|1024x768-16|$cirrus|16||--size 320x240"
  "cli-fb32|std|1024x768|$bochs|32||--size 640x480 --renderer scanline --aa 2 --shading gouraud"
  "cli-fb24|cirrus|800x600-24|$cirrus|24||--size 800x600 --band-rows 7 --buffers 2"
)

failed=0
report_fail() { echo "not ok $1: $2"; failed=1; }

kernel=""
if [ -n "${MASKLINE_QEMU_CACHE:-}" ]; then caches=("$MASKLINE_QEMU_CACHE"); else caches=(/var/cache/maskline/qemu-linux "$PWD/build/qemu-linux"); fi
for dir in "${caches[@]}"; do
  if [ -f "$dir/current/vmlinux" ]; then kernel="$dir/current"; break; fi
done

names=("$@")
selected=()
for c in "${configs[@]}"; do
  name=${c%%|*}
  if [ ${#names[@]} -eq 0 ] || [[ " ${names[*]} " == *" $name "* ]]; then selected+=("$c"); fi
done

missing=""
[ -n "$kernel" ] || missing="no kernel unpacked (tests/qemu-fbdev/fetch_kernel.sh, run by tools/bootstrap.sh, could not fetch linux-image-*-amd64)"
command -v qemu-system-x86_64 >/dev/null || missing="qemu-system-x86_64 is not installed"
busybox=/bin/busybox  # busybox-static: the guest has no shared libraries
[ -x "$busybox" ] || missing="busybox-static is not installed"
command -v cpio >/dev/null || missing="cpio is not installed"
[ -x "$guest" ] && [ -x "$check" ] || missing="$guest or $check is not built (make test builds them)"
if [ -n "$missing" ]; then
  for c in "${selected[@]}"; do report_fail "${c%%|*}" "not run: $missing"; done
  exit 1
fi

# ---- the initramfs: busybox, the modules, the guest program, an /init that reads its orders from
# the kernel command line (fbtest.mods=a,b,c) -------------------------------------------------------
work="$build/qemu-fbdev/run"
rm -rf "$work"
mkdir -p "$work/root/bin" "$work/root/dev" "$work/root/proc" "$work/root/sys" "$work/root/lib/fb"
cp "$busybox" "$work/root/bin/busybox"
cp "$kernel"/modules/*.ko "$work/root/lib/fb/"
cp "$guest" "$work/root/bin/fbtest"
if [ -x "$cli" ]; then strip -o "$work/root/bin/maskline" "$cli" 2>/dev/null || cp "$cli" "$work/root/bin/maskline"; fi
cat >"$work/root/init" <<'EOF'
#!/bin/busybox sh
bb=/bin/busybox
$bb mount -t devtmpfs dev /dev
$bb mount -t proc proc /proc
$bb mount -t sysfs sys /sys
mods=$($bb sed -n 's/.*fbtest\.mods=\([^ ]*\).*/\1/p' /proc/cmdline)
cli=$($bb sed -n 's/.*fbtest\.cli=\([^ ]*\).*/\1/p' /proc/cmdline | $bb tr , ' ')
args=$($bb sed -n 's/.*fbtest\.args=\([^ ]*\).*/\1/p' /proc/cmdline | $bb tr , ' ')
for m in $(echo "$mods" | $bb tr , ' '); do
  $bb insmod /lib/fb/${m%%:*}.ko $(case $m in *:*) echo "${m#*:}" | $bb tr : ' ' ;; esac) ||
    echo "FBTEST ERROR insmod $m failed"
done
i=0
while [ ! -e /dev/fb0 ] && [ $i -lt 50 ]; do $bb usleep 100000; i=$((i + 1)); done
if [ -n "$cli" ]; then
  # The real CLI draws; the guest program then only reports the screen.
  if /bin/maskline show $cli --display fb:/dev/fb0; then
    /bin/fbtest --info /dev/fb0
  else
    echo "FBTEST ERROR maskline show $cli exited with status $?"
  fi
else
  /bin/fbtest $args /dev/fb0 || echo "FBTEST ERROR the guest program exited with status $?"
fi
# Process 1 must never exit.
while true; do $bb sleep 3600; done
EOF
chmod +x "$work/root/init"
(cd "$work/root" && find . | cpio -o -H newc --quiet | gzip -1 >"$work/initramfs.cpio.gz") ||
  { for c in "${selected[@]}"; do report_fail "${c%%|*}" "cannot build the initramfs"; done; exit 1; }

# ---- one boot ---------------------------------------------------------------------------------
# Takes a screendump over the monitor into $1 and waits until the whole w x h picture is written.
screendump() {
  local file=$1 w=$2 h=$3 size waited=0
  size=$(( $(printf 'P6\n%d %d\n255\n' "$w" "$h" | wc -c) + w * h * 3 ))
  rm -f "$file"
  echo "screendump $file" >&7
  while [ "$(stat -c %s "$file" 2>/dev/null || echo 0)" -lt "$size" ] && [ $waited -lt 100 ]; do
    sleep 0.1
    waited=$((waited + 1))
  done
  [ "$(stat -c %s "$file" 2>/dev/null || echo 0)" -ge "$size" ]
}

# Boots, waits for the guest's READY line, then runs `check_screen` while QEMU still runs (it takes
# screendumps over the monitor, a pipe chardev: DIR/mon.in and DIR/mon.out), quits. Sets `ready` to
# the READY line or `why` to what went wrong.
boot() {
  local dir=$1 vga=$2 video=$3 mods=$4 args=$5 cliargs=$6
  mkdir -p "$dir"
  mkfifo "$dir/mon.in" "$dir/mon.out"
  : >"$dir/serial.log"
  timeout -k 5 "$boot_timeout" qemu-system-x86_64 -accel tcg -m 256 -smp 1 -nodefaults -no-user-config \
    -kernel "$kernel/vmlinux" -initrd "$work/initramfs.cpio.gz" \
    -append "console=ttyS0 quiet panic=-1 video=$video vt.global_cursor_default=0 fbtest.mods=${mods// /,} fbtest.args=${args// /,}${cliargs:+ fbtest.cli=${cliargs// /,}}" \
    -vga "$vga" -display none -serial "file:$dir/serial.log" -no-reboot -nic none \
    -chardev "pipe,id=mon,path=$dir/mon" -mon chardev=mon,mode=readline >"$dir/qemu.log" 2>&1 &
  local qemu=$!
  # Both ends of the fifos stay open on our side so that neither side blocks or sees EOF early.
  exec 7<>"$dir/mon.in" 8<>"$dir/mon.out"
  cat <&8 >"$dir/monitor.log" &
  local reader=$!
  local start=$SECONDS
  ready="" why=""
  while :; do
    if grep -aq '^FBTEST READY' "$dir/serial.log"; then ready=$(grep -a '^FBTEST READY' "$dir/serial.log" | head -n 1 | tr -d '\r'); break; fi
    if grep -aq '^FBTEST ERROR' "$dir/serial.log"; then why=$(grep -a '^FBTEST ERROR' "$dir/serial.log" | head -n 1 | tr -d '\r'); why=${why#FBTEST ERROR }; break; fi
    if ! kill -0 "$qemu" 2>/dev/null; then why="QEMU exited early: $(tail -n 1 "$dir/qemu.log")"; break; fi
    if [ $((SECONDS - start)) -ge "$boot_timeout" ]; then why="no READY line from the guest within $boot_timeout s"; break; fi
    sleep 0.2
  done
  [ -z "$ready" ] || check_screen
  echo "quit" >&7
  local waited=0
  while kill -0 "$qemu" 2>/dev/null && [ $waited -lt 100 ]; do sleep 0.1; waited=$((waited + 1)); done
  kill "$qemu" 2>/dev/null
  wait "$qemu" 2>/dev/null
  kill "$reader" 2>/dev/null
  wait "$reader" 2>/dev/null
  exec 7>&- 8>&-
  boot_seconds=$((SECONDS - start))
}

# Called by boot() once the guest is READY: checks the bits per pixel it got, compares a screendump
# with the expected picture (again each second, up to 4 screendumps, while it differs: DRM fbdev
# emulation copies to the display after a delay, which stretches when the host is busy). Sets
# `verdict` ("ok ..." or "not ok ...").
check_screen() {
  # FBTEST READY <width> <height> <bpp> <format> <direct|converted>
  local w h got_bpp format copy result attempt
  read -r _ _ w h got_bpp format copy <<<"$ready"
  if [ "$got_bpp" != "$bpp" ]; then
    verdict="not ok $name: the guest got a ${w}x${h} screen at $got_bpp bpp, not $bpp"
    return
  fi
  for attempt in 1 2 3 4; do
    if ! screendump "$dir/screen.ppm" "$w" "$h"; then
      verdict="not ok $name: QEMU wrote no complete screendump ($dir/monitor.log)"
      return
    fi
    if result=$("$check" "$dir/screen.ppm" "$bpp" "${expected[@]}" 2>&1); then
      verdict="ok $name: ${w}x${h} $bpp bpp as $format ($copy), screendump $result"
      [ $attempt -eq 1 ] || verdict="$verdict (screendump $attempt)"
      return
    fi
    verdict="not ok $name: $result after $attempt screendumps ($dir/screen.ppm)"
    [ $attempt -eq 4 ] || sleep 1
  done
}

timed_out=""
for c in "${selected[@]}"; do
  IFS='|' read -r name vga video mods bpp args cliargs <<<"$c"
  dir="$work/$name"
  mkdir -p "$dir"
  # A guest that never got ready once will most likely never: do not spend a minute on each.
  if [ -n "$timed_out" ]; then
    report_fail "$name" "not run: $timed_out timed out"
    continue
  fi
  expected=(pattern)
  if [ -n "$cliargs" ]; then
    if [ ! -x "$cli" ]; then
      report_fail "$name" "not run: $cli is not built (make test builds it)"
      continue
    fi
    # The same static CLI renders the reference frame on the host.
    # shellcheck disable=SC2086
    if ! "$cli" render $cliargs -o "$dir/host.png" >"$dir/host.log" 2>&1; then
      report_fail "$name" "the host render failed: $(tail -n 1 "$dir/host.log")"
      continue
    fi
    expected=(png "$dir/host.png")
  fi
  verdict=""
  boot "$dir" "$vga" "$video" "$mods" "$args" "$cliargs"
  if [ -z "$ready" ]; then
    report_fail "$name" "$why (serial log: $dir/serial.log)"
    case "$why" in "no READY line"*) timed_out=$name ;; esac
  elif [ "${verdict#ok }" != "$verdict" ]; then
    echo "$verdict, ${boot_seconds} s"
  else
    report_fail "$name" "${verdict#not ok $name: }"
  fi
done
exit $failed
