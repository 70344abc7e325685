#!/usr/bin/env bash
# Textured frames against the same frames untextured (part of make bench; docs/textures.md): one frame
# of each renderer at 320x240, 1 sample a pixel, flat shading, under callgrind. The untextured frame
# is the same scene compiled without its images (every material draws its colour). Also the texture
# pager's bytes read and resident peak. Rewrites the bench-textures section of docs/benchmarks.md.
# Usage: tools/bench/textures.sh BUILD [WORKDIR]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/doc_section.sh"
build=${1:-build}
work=${2:-$build/bench-work}
bench="$build/bench"
cli="$build/maskline"
mkdir -p "$work"
boxtex=/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb

# Each scene as compiled (its own samplers), with every sampler nearest and every sampler bilinear;
# the untextured baseline is shared: SCENE-plain for SCENE, SCENE-nearest and SCENE-bilinear.
for v in "" -plain -nearest -bilinear; do "$bench" prepare "banded$v" "$work/banded$v.mls" >/dev/null; done
scenes=(banded banded-nearest banded-bilinear)
if [ -f "$boxtex" ]; then
  "$bench" prepare "$boxtex" "$work/boxtextured.mls" >/dev/null
  for v in plain nearest; do "$bench" prepare "$v:$boxtex" "$work/boxtextured-$v.mls" >/dev/null; done
  scenes+=(boxtextured boxtextured-nearest)
fi
# A textured model of many small triangles: the COLLADA duck (4,212 triangles, a 256x256 TGA) converted
# to glTF by assimp, in a directory of its own with the texture beside it (the glb refers to
# ./duckCM.tga). Compiled as duck-textured.mls: run.sh's duck.mls, exported without the texture beside it,
# stays the untextured duck that quality.sh and the frame table measure. Its rows are labelled duck.
duck_dir=/usr/share/assimp/models/Collada
if [ -f "$duck_dir/duck.dae" ] && [ -f "$duck_dir/duckCM.tga" ] && command -v assimp >/dev/null; then
  mkdir -p "$work/duck-textured"
  cp "$duck_dir/duckCM.tga" "$work/duck-textured/"
  assimp export "$duck_dir/duck.dae" "$work/duck-textured/duck.glb" -f glb2 >/dev/null
  "$bench" prepare "$work/duck-textured/duck.glb" "$work/duck-textured.mls" >/dev/null
  for v in plain nearest mips; do "$bench" prepare "$v:$work/duck-textured/duck.glb" "$work/duck-$v.mls" >/dev/null; done
  scenes+=(duck-textured duck-nearest duck-mips)
fi

# The core's 16-row bands. The scanline renderer and the row "tiler, a band at a time" render them a
# band at a time, textured and untextured alike: with arena to spare the tiler renders several bands
# at once, a textured frame fewer than the same frame untextured where that keeps its texture
# residency (docs/displays.md, render bands), and that row's ratio is the texture work's alone. The
# row "tiler" renders them as bench frame does by default (as many at once as the arena holds), as the
# frame table measures it.
bands=16:16
# instructions SCENE RENDERER [AA [BANDS]] -> instructions of one frame (AA x AA samples a pixel, default 1)
instructions() {
  valgrind --tool=callgrind --instr-atstart=no --callgrind-out-file="$work/callgrind.textures" \
    "$bench" frame "$work/$1.mls" "$2" 320x240 "${3:-1}" flat "${4:-$bands}" 2>&1 >/dev/null | awk '/Collected/ { print $4 }'
}
# stat SCENE RENDERER KEY [BANDS] -> a field of the same frame's statistics (run natively)
stat() {
  "$bench" frame "$work/$1.mls" "$2" 320x240 1 flat "${4:-$bands}" | grep -o "\b$3=[0-9]*" | cut -d= -f2
}

echo "bench: textured frames against the same frames untextured (320x240, 1 sample a pixel, flat)"
rows=("| scene | renderer | textured | untextured | textured / untextured | texture bytes read | resident peak bytes | of all textures' pool bytes |"
      "|---|---|---:|---:|---:|---:|---:|---:|")
targets=()  # target_row lines (doc_section.sh)
for s in "${scenes[@]}"; do
  # every texture's bytes in the pool (each rounded to 4): the pager's desired pool
  total=$("$cli" info "$work/$s.mls" | awk '/^texture pool bytes/ { print $5 }')
  # renderer, bench frame's BAND_ROWS, row label
  for run in "scanline $bands scanline" "tiler $bands tiler, a band at a time" "tiler 16 tiler"; do
    read -r renderer frame_bands r <<<"$run"
    with=$(instructions "$s" "$renderer" 1 "$frame_bands")
    without=$(instructions "${s%%-*}-plain" "$renderer" 1 "$frame_bands")
    read_bytes=$(stat "$s" "$renderer" texture_bytes_loaded "$frame_bands")
    peak=$(stat "$s" "$renderer" texture_bytes_peak "$frame_bands")
    ratio=$(ratio "$with" "$without")
    share=$(ratio "$peak" "$total")
    rows+=("| ${s%-textured} | $r | $with | $without | $ratio | $read_bytes | $peak | $share of $total |")
    # The targets on each scene as its glTF asks (the -nearest, -bilinear and -mips variants are studies).
    case $s in
      banded|boxtextured|duck-textured)
        targets+=("$(target_row "${s%-textured}, $r, textured / untextured" "$(ratio "$with" "$without" 3)" 1.4)") ;;
    esac
    if [ "$s" = banded ]; then
      targets+=("$(target_row "banded, $r, peak resident / all textures' bytes" "$(ratio "$peak" "$total" 3)" 0.5)")
    fi
    echo "  ${s%-textured} $r: $with vs $without instructions ($ratio x), $read_bytes bytes read, peak $peak of $total"
  done
done
# The scanline renderer supersampled (3x3, each sample textured: the paper's filtering of texels).
if [[ " ${scenes[*]} " == *" duck-textured "* ]]; then
  with=$(instructions duck-textured scanline 3)
  without=$(instructions duck-plain scanline 3)
  ratio=$(ratio "$with" "$without")
  rows+=("| duck, 3x3 samples | scanline | $with | $without | $ratio | | | |")
  echo "  duck scanline 3x3: $with vs $without instructions ($ratio x)"
fi
# The banded scene with a pool of only its largest texture: the same image, with reloads.
min_pool=$("$cli" info "$work/banded.mls" | awk '/^texture pool bytes/ { print $NF == "largest)" ? $(NF - 2) : 0 }')
small=$("$cli" render "$work/banded.mls" --renderer scanline --stats --texture-pool "$min_pool" \
          --eye 0.4,0.3,5.6 --target 0,0,0 |
        grep -o '"texture_\(loads\|reloads\|bytes_loaded\)":[0-9]*' | tr '\n' ' ')

table=$(printf '%s\n' "${rows[@]}"; targets_table "Texture targets, measured in this run:" "${targets[@]}")
section=$(printf '%s\n' "<!-- bench-textures:begin (generated by make bench: tools/bench/textures.sh; do not edit by hand) -->" \
  "Measured $(date -u +%Y-%m-%d) on $(uname -m), $(valgrind --version), g++ -O2; instructions of one frame (callgrind)," \
  "320x240, one sample a pixel (the row marked 3x3: nine), flat shading, the default camera (the banded scene: its own). Untextured = the same scene compiled" \
  "without its images. banded = build_banded_scene() (four textured bands, most of the frame textured: three nearest, one" \
  "bilinear), boxtextured = BoxTextured.glb (about a third of the frame textured, one 256x256 texture of 8-bit palette," \
  "bilinear, minified, with mip levels: its sampler asks for them), duck = the COLLADA duck (4,212 small triangles, framed" \
  "as in the frame table, one 256x256 texture, bilinear); -nearest / -bilinear: the same scene with every sampler's filter" \
  "set so, -mips: compiled with every texture's mip levels (bench prepare)." \
  "Tiler: its bands rendered as bench frame does by default (as many at once as the arena holds, as in the frame table);" \
  "tiler, a band at a time, and scanline: each 16-row band alone, textured and untextured alike." \
  "" "$table" "" \
  "banded, scanline, texture pool of the largest texture only ($min_pool bytes; maskline render --texture-pool, same camera, same image): ${small% }." \
  "<!-- bench-textures:end -->")
write_doc_section bench-textures "Textured frames" "$section"
echo "bench: texture table written to docs/benchmarks.md"
