#!/usr/bin/env bash
# The firmware checks (docs/firmware.md): each board's ELF (make firmware) runs under qemu-system-arm
# with hard timeouts and its output is compared with the host's.
#   mps2-an385  the 320x240 RGB565 band bytes written through semihosting equal the host's bytes
#               (tools/board/fwtool ref) byte for byte, per renderer, and decode to `maskline render
#               --format rgb565`'s picture
#   lm3s6965evb QMP screendump of the SSD0323 OLED (512x256) equals `maskline show --display
#               emu:ssd0323 --zoom 4`, per renderer
#   microbit    the Cortex-M0+ build's CRC-32 of its frame equals the host's; that build has no textures
#               (ML_TEXTURES=0), and draws a textured model as the host draws it compiled without images
#   render-on-qemu with its own camera and options (scanline and tiler, antialiased) equals `maskline render`
#   every ELF   arm-none-eabi-nm shows no soft-float helper; the board images' code and tables fit 96 KB
# Usage: tests/firmware/run.sh BUILD
# Output: one line per check, "ok NAME: ..." or "not ok NAME: reason"; work files in BUILD/firmware/run/.
set -u

build=$(cd "${1:-build}" && pwd)
fw="$build/firmware"
fwtool="$fw/fwtool"
cli=${MASKLINE_CLI:-$build/maskline}
[ -x "$cli" ] || cli="$build/maskline"
here=$(cd "$(dirname "$0")" && pwd)
run="$fw/run"
limit=${MASKLINE_FIRMWARE_TIMEOUT:-30}  # seconds a QEMU run may take at most
rm -rf "$run"
mkdir -p "$run"

failed=0
ok() { echo "ok $1: $2"; }
not_ok() { echo "not ok $1: $2"; failed=1; }

missing=""
command -v qemu-system-arm >/dev/null || missing="qemu-system-arm is not installed"
command -v arm-none-eabi-nm >/dev/null || missing="arm-none-eabi-nm is not installed"
for f in "$fwtool" "$fw/mps2-an385-tiler.elf" "$fw/mps2-an385-scanline.elf" "$fw/lm3s6965evb-tiler.elf" "$fw/lm3s6965evb-scanline.elf" "$fw/m0plus.elf" "$fw/m0plus-boxtextured.elf"; do
  [ -e "$f" ] || missing="$f is missing (make firmware)"
done
if [ -n "$missing" ]; then
  for n in mps2-tiler-bytes mps2-scanline-bytes mps2-tiler-picture mps2-scanline-picture lm3s-tiler-oled \
    lm3s-scanline-oled m0plus-microbit-crc m0plus-without-textures render-on-qemu render-on-qemu-tiler-aa render-on-qemu-textured-tiler \
    render-on-qemu-textured-scanline render-on-qemu-small-textured-tiler render-on-qemu-small-textured-scanline \
    render-on-qemu-duck-tiler render-on-qemu-duck-scanline render-on-qemu-duck-nearest-tiler \
    render-on-qemu-duck-nearest-scanline flash-budget no-soft-float; do
    not_ok "$n" "$missing"
  done
  exit 1
fi

qemu_semihosting=(-semihosting-config enable=on,target=native -icount shift=0,sleep=off -monitor none -serial none)

# ---- mps2-an385: band bytes through semihosting ----------------------------------------------------
mkdir -p "$run/mps2"
for r in tiler scanline; do
  name="mps2-$r-bytes"
  board="$run/mps2/frame-$r.raw"
  (cd "$run/mps2" && timeout "$limit" qemu-system-arm -M mps2-an385 -nographic "${qemu_semihosting[@]}" \
    -kernel "$fw/mps2-an385-$r.elf" >out-$r.txt 2>err-$r.txt)
  rc=$?
  if [ $rc -ne 0 ]; then not_ok "$name" "QEMU exited with status $rc ($(tail -1 "$run/mps2/out-$r.txt" 2>/dev/null))"; continue; fi
  if ! "$fwtool" ref "$fw/scenes/default.mls" --renderer $r --size 320x240 --format rgb565 -o "$run/mps2/host-$r.raw" >>"$run/mps2/host.txt" 2>&1; then
    not_ok "$name" "fwtool ref failed"; continue
  fi
  instr=$(sed -n "s/^frame $r instructions \([0-9]*\).*/\1/p" "$run/mps2/out-$r.txt")
  if cmp -s "$board" "$run/mps2/host-$r.raw"; then
    ok "$name" "$(stat -c %s "$board") bytes equal the host's; $instr instructions a frame"
  else
    not_ok "$name" "$(cmp "$board" "$run/mps2/host-$r.raw" 2>&1 | head -1)"
  fi
  name="mps2-$r-picture"
  "$fwtool" topng "$board" --size 320x240 --format rgb565 -o "$run/mps2/board-$r.png" >/dev/null 2>&1
  "$cli" render "$fw/scenes/default.mls" --renderer $r --format rgb565 -o "$run/mps2/cli-$r.png" >/dev/null 2>&1
  if out=$("$fwtool" same "$run/mps2/board-$r.png" "$run/mps2/cli-$r.png" 2>&1); then
    ok "$name" "decoded frame equals maskline render --format rgb565 ($out)"
  else
    not_ok "$name" "$out"
  fi
done

# ---- lm3s6965evb: the OLED's screendump --------------------------------------------------------------
for r in tiler scanline; do
  name="lm3s-$r-oled"
  dir="$run/lm3s-$r"
  mkdir -p "$dir"
  sockdir=$(mktemp -d /tmp/maskline-qmp.XXXXXX)  # a short path: unix socket names are limited to 107 bytes
  sock="$sockdir/qmp.sock"
  timeout "$limit" qemu-system-arm -M lm3s6965evb -display none "${qemu_semihosting[@]}" \
    -kernel "$fw/lm3s6965evb-$r.elf" -qmp "unix:$sock,server=on,wait=off" >"$dir/out.txt" 2>"$dir/err.txt" &
  pid=$!
  shown=0
  for _ in $(seq 1 $((limit * 10))); do
    if grep -q "^frame shown" "$dir/out.txt" 2>/dev/null; then shown=1; break; fi
    kill -0 $pid 2>/dev/null || break
    sleep 0.1
  done
  if [ $shown -eq 1 ]; then
    perl "$here/qmp.pl" "$sock" "$dir/oled.ppm" >>"$dir/err.txt" 2>&1 || shown=0
  fi
  kill $pid 2>/dev/null
  wait $pid 2>/dev/null
  rm -rf "$sockdir"
  if [ $shown -eq 0 ] || [ ! -s "$dir/oled.ppm" ]; then
    not_ok "$name" "no frame shown or no screendump ($(tail -1 "$dir/out.txt" 2>/dev/null))"
    continue
  fi
  "$cli" show "$fw/scenes/small.mls" --display emu:ssd0323 --renderer $r -o "$dir/host.png" --zoom 4 >/dev/null 2>>"$dir/err.txt"
  instr=$(sed -n "s/^frame $r instructions \([0-9]*\).*/\1/p" "$dir/out.txt")
  if out=$("$fwtool" same "$dir/oled.ppm" "$dir/host.png" 2>&1); then
    if [[ "$out" == *", 1 colours" ]]; then not_ok "$name" "the picture is blank ($out)"
    else ok "$name" "screendump equals the host emulator ($out); $instr instructions a frame"; fi
  else
    not_ok "$name" "$out"
  fi
done

# ---- Cortex-M0+ on the microbit: CRC of the frame ----------------------------------------------------
name="m0plus-microbit-crc"
mkdir -p "$run/m0plus"
if (cd "$run/m0plus" && timeout "$limit" qemu-system-arm -M microbit -nographic "${qemu_semihosting[@]}" \
  -kernel "$fw/m0plus.elf" >out.txt 2>err.txt); then
  board=$(sed -n 's/^frame tiler .* crc \(0x[0-9a-f]*\).*/\1/p' "$run/m0plus/out.txt")
  instr=$(sed -n 's/^frame tiler instructions \([0-9]*\).*/\1/p' "$run/m0plus/out.txt")
  "$fwtool" ref "$fw/scenes/small.mls" --renderer tiler --size 128x64 --format grey4 -o "$run/m0plus/host.raw" >/dev/null 2>&1
  host=$("$fwtool" crc "$run/m0plus/host.raw" 2>&1)
  if [ -n "$board" ] && [ "$board" = "$host" ]; then ok "$name" "CRC $board equals the host's; $instr instructions a frame"
  else not_ok "$name" "board CRC '$board', host CRC '$host'"; fi
else
  not_ok "$name" "QEMU exited with status $? ($(tail -1 "$run/m0plus/out.txt" 2>/dev/null))"
fi

# ---- Cortex-M0+ without textures: a textured model in its base colours, the fallback counted -----------
name="m0plus-without-textures"
dir="$run/m0plus-boxtextured"
mkdir -p "$dir"
glb=$(sed -n 's/^FW_TEXTURED_GLB := //p' "$here/../../Makefile")
if (cd "$dir" && timeout "$limit" qemu-system-arm -M microbit -nographic "${qemu_semihosting[@]}" \
  -kernel "$fw/m0plus-boxtextured.elf" >out.txt 2>err.txt); then
  board=$(sed -n 's/^frame tiler .* crc \(0x[0-9a-f]*\).*/\1/p' "$dir/out.txt")
  fallbacks=$(grep -o '"texture_fallbacks":[0-9]*' "$dir/out.txt" | cut -d: -f2)
  "$fwtool" scene "plain:$glb" -o "$dir/plain.mls" >/dev/null 2>&1
  "$fwtool" ref "$dir/plain.mls" --renderer tiler --size 128x64 --format grey4 -o "$dir/plain.raw" >/dev/null 2>&1
  "$fwtool" ref "$fw/scenes/boxtextured.mls" --renderer tiler --size 128x64 --format grey4 -o "$dir/textured.raw" \
    >/dev/null 2>&1
  plain=$("$fwtool" crc "$dir/plain.raw" 2>&1)
  textured=$("$fwtool" crc "$dir/textured.raw" 2>&1)
  if [ -z "$board" ] || [ "$board" != "$plain" ]; then not_ok "$name" "board CRC '$board', host without images '$plain'"
  elif [ "$plain" = "$textured" ]; then not_ok "$name" "the model looks the same with and without its texture ($plain)"
  elif [ "$fallbacks" != 1 ]; then not_ok "$name" "texture_fallbacks '$fallbacks', expected 1 (its one texture)"
  else ok "$name" "CRC $board equals the host's frame of the model without images (textured: $textured); 1 fallback"; fi
else
  not_ok "$name" "QEMU exited with status $? ($(tail -1 "$dir/out.txt" 2>/dev/null))"
fi

# ---- tools/board/render-on-qemu: own camera and options, against maskline render -----------------------
# render_on_qemu NAME WHAT SCENE OPTIONS...: the board's frame of SCENE with OPTIONS against maskline render's
render_on_qemu() {
  local name=$1 what=$2 scene=$3 dir="$run/$1" json out
  shift 3
  mkdir -p "$dir"
  if ! json=$(env -u MAKEFLAGS -u MAKELEVEL BUILD="$build" MASKLINE_FIRMWARE_TIMEOUT="$limit" \
    "$here/../../tools/board/render-on-qemu" "$scene" "$@" -o "$dir/board.png" --stats 2>"$dir/err.txt"); then
    not_ok "$name" "failed: $(tail -1 "$dir/err.txt")"
    return
  fi
  "$cli" render "$scene" "$@" --format rgb565 -o "$dir/cli.png" >/dev/null 2>&1
  if ! out=$("$fwtool" same "$dir/board.png" "$dir/cli.png" 2>&1); then
    not_ok "$name" "$out"
  elif ! [[ "$json" == *'"instructions":'[1-9]* && "$json" == *'"flash_bytes":'[1-9]* && "$json" == *'"ram_high_water_bytes":'[1-9]* ]]; then
    not_ok "$name" "--stats lacks instructions, flash_bytes or ram_high_water_bytes: $json"
  else
    ok "$name" "$what equals maskline render ($out)"
  fi
}
render_on_qemu render-on-qemu "160x120 scanline aa 2 gouraud with its own eye" "$fw/scenes/default.mls" \
  --renderer scanline --aa 2 --shading gouraud --size 160x120 --eye 6,4,8 --target 0,1,0
render_on_qemu render-on-qemu-tiler-aa "160x120 tiler aa 4 (box filter) in 8-row bands" "$fw/scenes/default.mls" \
  --renderer tiler --aa 4 --band-rows 8 --size 160x120
# A 90,819-byte texture (with its mip levels) on a 64 KB board: sampled in place from the flash blob.
box_textured=/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb
for r in tiler scanline; do
  render_on_qemu "render-on-qemu-textured-$r" "BoxTextured (texels read in place from flash) with the $r" "$box_textured" \
    --renderer $r --size 160x120
done
# Small textured triangles (docs/textures.md): at 160x120 most of textureTransform's triangles are small,
# their coordinates from box sums (the boards' loop form, divisions by div_floor) and nearest texels.
texture_transform=/usr/share/assimp/models/glTF2/textureTransform/TextureTransformTest.gltf
for r in tiler scanline; do
  render_on_qemu "render-on-qemu-small-textured-$r" "textureTransform's small triangles with the $r" \
    "$texture_transform" --renderer $r --size 160x120
done
# Small bilinear triangles in a flat colour (filtered, then multiplied: docs/textures.md): the COLLADA
# duck (4,212 triangles, a 256x256 palette texture), converted by assimp with its texture beside it;
# and compiled --texture-filter nearest, its small triangles' texels from the texture's white table.
duck_dir=/usr/share/assimp/models/Collada
mkdir -p "$run/duck-model"
if cp "$duck_dir/duckCM.tga" "$run/duck-model/" 2>/dev/null &&
  assimp export "$duck_dir/duck.dae" "$run/duck-model/duck.glb" -f glb2 >/dev/null 2>&1 &&
  "$cli" compile "$run/duck-model/duck.glb" -o "$run/duck-model/duck.mls" >/dev/null 2>&1 &&
  "$cli" compile "$run/duck-model/duck.glb" -o "$run/duck-model/duck-nearest.mls" --texture-filter nearest >/dev/null 2>&1; then
  for r in tiler scanline; do
    render_on_qemu "render-on-qemu-duck-$r" "the textured duck's small bilinear triangles with the $r" \
      "$run/duck-model/duck.mls" --renderer $r --size 160x120
    render_on_qemu "render-on-qemu-duck-nearest-$r" "the duck's small nearest triangles with the $r" \
      "$run/duck-model/duck-nearest.mls" --renderer $r --size 160x120
  done
else
  for r in tiler scanline; do
    for n in "render-on-qemu-duck-$r" "render-on-qemu-duck-nearest-$r"; do not_ok "$n" "the duck could not be converted and compiled"; done
  done
fi

# ---- flash budget: code and tables of each board image -----------------------------------------------
# Code, read-only data, the mask tables and .data's initial values must stay within 96 KB of flash
# (docs/firmware.md, "Flash"), whatever the scene: the scene is flashed after them. The diagnostic
# image with both renderers (mps2-an385-calls) is exempt.
flash_budget=98304
for elf in "$fw"/*.elf; do
  image=$(basename "$elf" .elf)
  [ "$image" = mps2-an385-calls ] && continue
  bytes=$(arm-none-eabi-size -A "$elf" | awk '$1 == ".text" || $1 == ".ARM.exidx" || $1 == ".tables" || $1 == ".data" { n += $2 } END { print n + 0 }')
  if [ "$bytes" -gt 0 ] && [ "$bytes" -le "$flash_budget" ]; then
    ok "flash-budget $image" "code and tables $bytes of $flash_budget bytes ($((flash_budget - bytes)) left)"
  else not_ok "flash-budget $image" "code and tables $bytes bytes, over the $flash_budget-byte budget"; fi
done

# ---- no soft-float helper in any ELF ------------------------------------------------------------------
# Symbol names on stdin; prints the soft-float ones (libgcc's __aeabi_f*/d*/c[fd]*, conversions,
# __addsf3-style arithmetic and comparisons, __fix*/__float* conversions).
soft_float() {
  grep -E '^__aeabi_([fd]|c[fd]|[ilu]+2[fd])|^__[a-z]+[sdtx]f[23]$|^__(fix|fixuns)[sdtx]f[sdt]i$|^__(float|floatun)[sdt]i[sdtx]f$' | sort -u
}
# The filter itself: it must flag every soft-float helper below and no integer helper.
flagged=$(printf '%s\n' __aeabi_fadd __aeabi_dmul __aeabi_f2d __aeabi_i2f __aeabi_ul2d __aeabi_l2f __aeabi_cdcmple \
  __aeabi_d2iz __addsf3 __divdf3 __extendsfdf2 __truncdfsf2 __fixdfsi __fixunssfdi __floatsisf __floatundidf __eqsf2 \
  __ltdf2 __unordsf2 __powidf2 | soft_float | wc -l)
unflagged=$(printf '%s\n' __aeabi_ldivmod __aeabi_uldivmod __aeabi_lmul __aeabi_idiv __aeabi_uidivmod __aeabi_idiv0 \
  __aeabi_llsl __aeabi_lasr __divdi3 __udivmoddi4 __ctzdi2 __clzsi2 __muldi3 __divsi3 | soft_float | wc -l)
if [ "$flagged" -eq 20 ] && [ "$unflagged" -eq 0 ]; then ok "soft-float-filter" "flags all 20 soft-float helpers and none of 14 integer helpers"
else not_ok "soft-float-filter" "flags $flagged of 20 soft-float helpers and $unflagged of 14 integer helpers"; fi
for elf in "$fw"/*.elf; do
  name="no-soft-float $(basename "$elf")"
  found=$(arm-none-eabi-nm "$elf" | awk '{print $NF}' | soft_float | tr '\n' ' ')
  helpers=$(arm-none-eabi-nm "$elf" | awk '{print $NF}' | grep -E '^__aeabi_|^__[a-z]+[sd]i[234]$' | grep -v '0$' | sort -u | tr '\n' ' ')
  if [ -z "$found" ]; then ok "$name" "no soft-float helper linked (runtime helpers: ${helpers% })"
  else not_ok "$name" "soft-float helpers linked: $found"; fi
done

exit $failed
