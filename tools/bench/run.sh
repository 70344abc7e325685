#!/usr/bin/env bash
# make bench: instructions per frame (callgrind, frame only) for the tiler, the scanline renderer and an
# integer z-buffer baseline. Prints a table and rewrites the generated section of docs/benchmarks.md.
# Usage: tools/bench/run.sh BUILD
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/doc_section.sh"
build=${1:-build}
bench="$build/bench"
work="$build/bench-work"
mkdir -p "$work"
command -v valgrind >/dev/null || { echo "bench: valgrind is missing (run tools/bootstrap.sh)"; exit 1; }
[ -x "$bench" ] || { echo "bench: $bench is missing (make bench builds it)"; exit 1; }

engine=/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb
# A screen-filling model of a few thousand triangles: the COLLADA duck (4,212 triangles), converted to
# glTF 2.0 by assimp (Debian's assimp-utils, installed by tools/bootstrap.sh).
duck_dae=/usr/share/assimp/models/Collada/duck.dae
scenes=(default office:8 tessellated:100000)
[ -f "$engine" ] && scenes=(engine "${scenes[@]}")
if [ -f "$duck_dae" ] && command -v assimp >/dev/null; then
  assimp export "$duck_dae" "$work/duck.glb" -f glb2 >/dev/null && scenes+=(duck)
else
  echo "bench: no duck model (needs assimp-testmodels and assimp-utils: tools/bootstrap.sh)"
fi

echo "bench: compiling scenes (natively, not measured)"
for s in "${scenes[@]}"; do
  name=${s%%:*}
  src=$s
  [ "$name" = engine ] && src=$engine
  [ "$name" = duck ] && src=$work/duck.glb
  "$bench" prepare "$src" "$work/$name.mls"
done

# field KEY LINE: value of key=value in a stats line
field() { { grep -o "\b$1=[^ ]*" <<<"$2" || true; } | head -1 | cut -d= -f2; }

rows=()
declare -A base_ir all_ir arena_bound per_tiled_ir split_of
# measure NAME RENDERER SIZE AA [SHADING [BANDS]] -> appends a table row. BANDS: bench frame's
# BAND_ROWS[:RENDER_ROWS] (default 16, the core's: the tiler renders as many bands at once as its spare
# arena holds, the whole frame); 16:16 renders them a band at a time (a row "tiler, a band at a time").
measure() {
  local name=$1 renderer=$2 size=$3 aa=$4 shading=${5:-flat} bands=${6:-16}
  local out="$work/callgrind.$name.$renderer.$size.$aa.$shading.${bands/:/-}"
  local line
  line=$(valgrind --tool=callgrind --instr-atstart=no --callgrind-out-file="$out" \
           "$bench" frame "$work/$name.mls" "$renderer" "$size" "$aa" "$shading" "$bands" 2>"$out.log") || {
    echo "bench: $name $renderer $size aa $aa failed: $(tail -1 "$out.log")"
    rows+=("| $name | $renderer | $size | $aa | failed | | | | | | | | | |")
    return 0
  }
  local ir
  ir=$({ grep -E '^totals:' "$out" || true; } | head -1 | awk '{print $2}')
  [ -n "$ir" ] || ir=$({ grep -o 'Collected : [0-9]*' "$out.log" || true; } | awk '{print $3}')
  local w=${size%x*} h=${size#*x}
  local per_pixel
  per_pixel=$(awk -v i="$ir" -v p="$((w * h))" 'BEGIN { printf "%.0f", i / p }')
  local ratio=""
  local label=$renderer
  [ "$bands" = 16 ] || label="$renderer, a band at a time"
  if [ "$renderer" = zbuffer ]; then
    base_ir["$name.$size"]=$ir
    ratio="1.00"
  elif [ -n "${base_ir[$name.$size]:-}" ]; then
    ratio=$(awk -v a="$ir" -v b="${base_ir[$name.$size]}" 'BEGIN { printf "%.2f", a / b }')
  fi
  local cells peak shade geo mmax n reuse
  cells=$(field cells_per_pixel "$line"); peak=$(field peak_arena_bytes "$line")
  [ "$renderer" = zbuffer ] && peak="$(field buffer_bytes "$line") (buffers)"
  shade=$(field shading_calls "$line"); geo=$(field geometry_samples "$line")
  mmax=$(field m_max "$line"); n=$(field n "$line")
  reuse=""
  if [ -n "$shade" ] && [ -n "$geo" ] && [ "$geo" != 0 ]; then
    reuse=$(awk -v a="$shade" -v b="$geo" 'BEGIN { printf "%.3f", a / b }')
  fi
  [ "$renderer" = tiler ] || cells=""
  [ "$renderer" = scanline ] || { mmax=""; n=""; reuse=""; }
  local tiled per_tiled="" split
  tiled=$(field triangles_tiled "$line"); split=$(field split_ratio "$line")
  if [ "$renderer" = tiler ] && [ -n "$tiled" ] && [ "$tiled" != 0 ]; then
    per_tiled=$(awk -v i="$ir" -v t="$tiled" 'BEGIN { printf "%.0f", i / t }')
    # the key ratios are point-sampled frames as the core renders them by default
    [ "$aa" = 1 ] && [ "$bands" = 16 ] && per_tiled_ir["$name.$size"]=$per_tiled
  fi
  split_of["$name"]=$split
  all_ir["$name.$label.$size.$aa"]=$ir
  if [ "$renderer" = scanline ]; then  # the least arena (render_arena_bytes), the peak with the spare bytes, the bound
    arena_bound["$name.$aa"]="$(field arena_bytes "$line") $peak $((16 * n + 64 * mmax + 16 * w))"
  fi
  local tris
  tris=$(field triangles "$line")
  local scene=$name
  [ -n "${5:-}" ] && [ -z "${6:-}" ] && scene="$name ($shading)"
  rows+=("| $scene | $label | $size | $aa | $ir | $per_pixel | $ratio | ${per_tiled:-} | ${split:-} | ${cells:-} | ${peak:-} | ${reuse:-} | ${mmax:-} | ${n:-} |")
  echo "  $name $label $size aa$aa: $ir instructions ($per_pixel/pixel) ${ratio:+x$ratio baseline}${per_tiled:+ $per_tiled/tiled triangle} [$tris triangles]"
}

start=$SECONDS
echo "bench: tiler against the z-buffer baseline"
for name in engine office default duck; do
  [ -f "$work/$name.mls" ] || continue
  sizes=(320x240 1024x768)
  case $name in default|duck) sizes=(320x240 128x64) ;; esac
  for size in "${sizes[@]}"; do
    measure "$name" zbuffer "$size" 1
    measure "$name" tiler "$size" 1
    # With the least arena's band structure (each band walked apart, with the band plan).
    [ "$size" = 128x64 ] || measure "$name" tiler "$size" 1 flat 16:16
  done
done
echo "bench: tiler at 8x8 samples a pixel (box and cosine-hump filters, jittered samples)"
for name in engine default; do
  [ -f "$work/$name.mls" ] || continue
  measure "$name" tiler 320x240 8
  measure "$name" tiler 320x240 8,cosine
  measure "$name" tiler 320x240 8,jittered
done
echo "bench: scanline at 1x1, 3x3, 4x4"
# office last: densely occluded (hundreds of active spans a row), the supersampled sweep's worst case.
scanline_scenes=(engine tessellated default duck office)
for name in "${scanline_scenes[@]}"; do
  [ -f "$work/$name.mls" ] || continue
  # The smooth model is shaded as the paper's are (Gouraud: a surface is a whole smooth batch).
  shading=flat
  [ "$name" = tessellated ] && shading=gouraud
  for aa in 1 3 4; do measure "$name" scanline 320x240 "$aa" "$shading"; done
done

header="| scene | renderer | size | aa | instructions/frame | per pixel | vs z-buffer | per tiled triangle | split ratio | cells/pixel | peak arena bytes | shading_calls/geometry_samples | m_max | n |"
sep="|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
table=$(printf '%s\n%s\n' "$header" "$sep"; printf '%s\n' "${rows[@]}")
notes=("" "Key ratios:")
for name in "${scanline_scenes[@]}"; do
  [ -n "${all_ir[$name.scanline.320x240.1]:-}" ] || continue
  one=${all_ir[$name.scanline.320x240.1]:-}
  notes+=("- $name, scanline 3x3 / 1x1: $(ratio "${all_ir[$name.scanline.320x240.3]:-}" "$one"); 4x4 / 1x1: $(ratio "${all_ir[$name.scanline.320x240.4]:-}" "$one")")
  for aa in 1 3 4; do
    b=${arena_bound[$name.$aa]:-}
    read -r least peak bound <<<"$b"
    [ -n "$b" ] && notes+=("- $name, scanline ${aa}x${aa}: least arena $least bytes (peak $peak with the spare bytes' vertex cache) against 16 n + 64 m_max + 16 width = $bound")
  done
done
notes+=("- engine 320x240, scanline 1x1 / tiler: $(ratio "${all_ir[engine.scanline.320x240.1]:-}" "${all_ir[engine.tiler.320x240.1]:-}")")
for name in engine default; do
  [ -n "${all_ir[$name.tiler.320x240.8]:-}" ] && notes+=("- $name 320x240, tiler 8x8 / 1x1: $(ratio "${all_ir[$name.tiler.320x240.8]}" "${all_ir[$name.tiler.320x240.1]:-}"); 8x8 cosine-hump / 1x1: $(ratio "${all_ir[$name.tiler.320x240.8,cosine]:-}" "${all_ir[$name.tiler.320x240.1]:-}"); 8x8 jittered / 1x1: $(ratio "${all_ir[$name.tiler.320x240.8,jittered]:-}" "${all_ir[$name.tiler.320x240.1]:-}")")
done
for name in default duck engine; do
  [ -n "${per_tiled_ir[$name.320x240]:-}" ] && notes+=("- $name 320x240, tiler instructions per tiled triangle (frame / Stats::triangles_tiled): ${per_tiled_ir[$name.320x240]}")
done
split_note="- BSP split ratio (pieces / triangles):"
for name in engine office tessellated default duck; do
  [ -n "${split_of[$name]:-}" ] && split_note+=" $name ${split_of[$name]};"
done
notes+=("${split_note%;}")
for label in tiler "tiler, a band at a time"; do
  notes+=("- engine, $label, 1024x768 / 320x240: $(ratio "${all_ir[engine.$label.1024x768.1]:-}" "${all_ir[engine.$label.320x240.1]:-}")")
done
notes+=("- office, tiler / z-buffer: 320x240 $(ratio "${all_ir[office.tiler.320x240.1]:-}" "${all_ir[office.zbuffer.320x240.1]:-}"), 1024x768 $(ratio "${all_ir[office.tiler.1024x768.1]:-}" "${all_ir[office.zbuffer.1024x768.1]:-}")")
# The speed targets (the speed issue; docs/tiler.md and docs/scanline.md say where the costs lie).
targets=()
targets+=("$(target_row "engine, tiler, 320x240 (instructions)" "${all_ir[engine.tiler.320x240.1]:-}" 63000000)")
targets+=("$(target_row "engine, tiler, 1024x768" "${all_ir[engine.tiler.1024x768.1]:-}" 81000000)")
targets+=("$(target_row "engine, tiler, 1024x768 / 320x240" \
  "$(ratio "${all_ir[engine.tiler.1024x768.1]:-}" "${all_ir[engine.tiler.320x240.1]:-}" 3)" 1.3)")
targets+=("$(target_row "engine, scanline 1x1, 320x240" "${all_ir[engine.scanline.320x240.1]:-}" 104000000)")
targets+=("$(target_row "default, tiler, instructions per tiled triangle" "${per_tiled_ir[default.320x240]:-}" 1200)")
for name in "${scanline_scenes[@]}"; do
  targets+=("$(target_row "$name, scanline 3x3 / 1x1" \
    "$(ratio "${all_ir[$name.scanline.320x240.3]:-}" "${all_ir[$name.scanline.320x240.1]:-}" 3)" 2.0)")
done
table=$(printf '%s\n' "$table" "${notes[@]}"; targets_table "Speed targets, measured in this run:" "${targets[@]}")
echo
echo "$table"
echo
echo "bench: done in $((SECONDS - start)) s"

doc=docs/benchmarks.md
section=$(printf '%s\n' "<!-- bench:begin (generated by make bench; do not edit by hand) -->" \
  "Measured $(date -u +%Y-%m-%d) on $(uname -m), $(valgrind --version), g++ -O2; instructions of one frame (callgrind)." \
  "Scenes: engine = 2CylinderEngine.glb, office = build_office_scene(8) seen down its rows, tessellated = build_tessellated_scene(100000), default = the bundled scene (build_default_scene), duck = the COLLADA duck (4,212 triangles) converted to glTF by assimp, framed to fill the screen." \
  "" "$table" "<!-- bench:end -->")
write_doc_section bench "Instructions per frame" "$section"
echo "bench: table written to $doc"
bash tools/bench/textures.sh "$build" "$work"
bash tools/bench/bands.sh "$build" "$work"
echo "bench: display tables written to $doc"
bash tools/bench/quality.sh "$build" "$work"
