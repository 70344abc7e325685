#!/usr/bin/env bash
# The boards in numbers (make bench-board, docs/firmware.md): each firmware image of `make firmware`
# runs under qemu-system-arm with -icount (one instruction a nanosecond, SysTick counting them) and
# reports, over semihosting, instructions a frame, flash and RAM. Rewrites the bench-board section of
# docs/benchmarks.md. Usage: tools/bench/board.sh BUILD
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/doc_section.sh"
build=${1:-build}
fw="$build/firmware"
work="$build/bench-work/board"
mkdir -p "$work"
command -v qemu-system-arm >/dev/null || { echo "bench-board: qemu-system-arm is missing (run tools/bootstrap.sh)"; exit 1; }
qemu=(-semihosting-config enable=on,target=native -icount shift=0,sleep=off -monitor none -serial none)

# run NAME MACHINE ELF: the image's report in $work/NAME.txt (boards that wait after the frame are
# stopped once they print "frame shown")
run() {
  local name=$1 machine=$2 elf out
  elf=$(realpath "$3")
  out=$(realpath "$work")/$1.txt
  # Semihosting writes the frame files into the current directory: keep them in $work.
  (cd "$work" && exec timeout 30 qemu-system-arm -M "$machine" -display none "${qemu[@]}" -kernel "$elf") >"$out" 2>/dev/null &
  local pid=$!
  for _ in $(seq 1 300); do
    kill -0 $pid 2>/dev/null || break
    grep -q '^frame shown' "$out" && break
    sleep 0.1
  done
  kill $pid 2>/dev/null || true
  wait $pid 2>/dev/null || true
}
value() { sed -n "s/^$1 \\([0-9]*\\).*/\\1/p" "$2" | head -1; }

rows=("| image | CPU | scene | frame | renderer | instructions/frame | arena bytes | stack high-water | code | tables | scene bytes | flash of |"
      "|---|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|")
add() {  # add IMAGE CPU SCENE FRAME RENDERER REPORT
  local r=$5 f=$6 arena
  arena=$(sed -n "s/^arena_needed $r \\([0-9]*\\).*/\\1/p;s/^arena_needed \\([0-9]*\\)$/\\1/p" "$f" | head -1)
  rows+=("| $1 | $2 | $3 | $4 | $r | $(value "frame $r instructions" "$f") | ${arena:-} | $(value "memory stack_high_water_bytes" "$f") | $(value "memory code_bytes" "$f") | $(value "memory tables_bytes" "$f") | $(value "memory scene_bytes" "$f") | $(value "memory flash_size" "$f") |")
}
for r in tiler scanline; do
  run "mps2-$r" mps2-an385 "$fw/mps2-an385-$r.elf"
  add mps2-an385 "Cortex-M3" "bundled (3,826 triangles)" "320x240 RGB565" $r "$work/mps2-$r.txt"
done
for r in tiler scanline; do
  run "lm3s-$r" lm3s6965evb "$fw/lm3s6965evb-$r.elf"
  add lm3s6965evb "Cortex-M3" "bundled (3,826 triangles)" "128x64 Grey4 OLED" $r "$work/lm3s-$r.txt"
done
run m0plus microbit "$fw/m0plus.elf"
add "m0plus (microbit)" "Cortex-M0+ code" "bundled (3,826 triangles)" "128x64 Grey4" tiler "$work/m0plus.txt"

# A textured model on the board: the COLLADA duck (4,212 triangles, one 256x256 palette texture,
# bilinear) as textures.sh converts it, rendered by tools/board/render-on-qemu on the mps2-an385 image
# (texels sampled in place from flash), compiled as its glTF asks and with every texture nearest
# (maskline compile --texture-filter nearest), against the same scene compiled without its images.
duck_dir=/usr/share/assimp/models/Collada
ratios=()
# add_json IMAGE CPU SCENE FRAME RENDERER JSON: a row from render-on-qemu's --stats line
add_json() {
  local j=$6
  field() { grep -o "\"$1\":[0-9]*" <<<"$j" | cut -d: -f2; }
  rows+=("| $1 | $2 | $3 | $4 | $5 | $(field instructions) | $(field peak_arena_bytes) | $(field stack_high_water_bytes) | $(field flash_code_bytes) | $(field flash_tables_bytes) | $(field flash_scene_bytes) | 4194304 |")
}
if [ -f "$duck_dir/duck.dae" ] && [ -f "$duck_dir/duckCM.tga" ] && command -v assimp >/dev/null; then
  mkdir -p "$work/duck-textured"
  cp "$duck_dir/duckCM.tga" "$work/duck-textured/"
  assimp export "$duck_dir/duck.dae" "$work/duck-textured/duck.glb" -f glb2 >/dev/null
  "$build/bench" prepare "$work/duck-textured/duck.glb" "$work/duck.mls" >/dev/null
  "$build/bench" prepare "plain:$work/duck-textured/duck.glb" "$work/duck-plain.mls" >/dev/null
  "$build/bench" prepare "nearest:$work/duck-textured/duck.glb" "$work/duck-nearest.mls" >/dev/null
  declare -A label=([duck]="textured (bilinear)" [duck-nearest]="textured, nearest" [duck-plain]="untextured")
  for r in tiler scanline; do
    declare -A count=()
    for s in duck duck-nearest duck-plain; do
      json=$(BUILD="$build" tools/board/render-on-qemu "$work/$s.mls" -o "$work/$s-$r.png" --renderer $r --size 160x120 --stats | tail -1)
      add_json mps2-an385 "Cortex-M3" "duck (4,212 triangles), ${label[$s]}" "160x120 RGB565" $r "$json"
      count[$s]=$(grep -o '"instructions":[0-9]*' <<<"$json" | cut -d: -f2)
    done
    ratios+=("$r $(awk -v a="${count[duck]}" -v n="${count[duck-nearest]}" -v b="${count[duck-plain]}" \
      'BEGIN { printf "%.2f (nearest %.2f)", a / b, n / b }')")
  done
else
  echo "bench-board: no duck model (needs assimp-testmodels and assimp-utils: tools/bootstrap.sh)"
fi
# helpers ELF...: the runtime helper functions linked (__aeabi_*, libgcc's __*si3/__*di2 ...), comma-separated
helpers() { for elf in "$@"; do arm-none-eabi-nm "$elf"; done | awk '$2 == "T" && ($3 ~ /^__aeabi_/ || $3 ~ /^__.*[sd]i[0-9]$/) { print $3 }' | sort -u | paste -sd, | sed 's/,/, /g'; }
helpers_m3=$(helpers "$fw/mps2-an385-tiler.elf" "$fw/mps2-an385-scanline.elf")
helpers_m0=$(helpers "$fw/m0plus.elf")

section=$(printf '%s\n' "<!-- bench-board:begin (generated by make bench-board; do not edit by hand) -->" \
  "Measured $(date -u +%Y-%m-%d) with $(qemu-system-arm --version | head -1), -icount shift=0 (instructions, not cycles)." "" \
  "${rows[@]}" "" \
  "${ratios:+The duck on the Cortex-M3 (texels read in place from the flash blob), textured / untextured: $(IFS=';'; echo "${ratios[*]}" | sed 's/;/, /g').}" \
  "" "Runtime helpers linked, Cortex-M3: ${helpers_m3:-none}; Cortex-M0+: ${helpers_m0:-none}. No soft-float helper (make test checks it)." \
  "<!-- bench-board:end -->")
printf '%s\n' "${rows[@]}"
write_doc_section bench-board "Boards" "$section"
echo "bench-board: table written to docs/benchmarks.md"
