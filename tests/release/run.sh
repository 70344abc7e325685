#!/usr/bin/env bash
# The release CLI (-O2: build/maskline, what users and the benchmarks run) against the sanitized one
# (-O1 with ASan and UBSan: build/san/maskline, what every other test runs): the same pictures, byte
# for byte. Only the optimizer differs between them, so a frame that differs is a piece of src/ the
# optimizer miscompiled or that relies on undefined behaviour (GCC 12's SLP vectorizer once took two
# __builtin_ctz in texture/mapping.cpp for one: docs/design.md). Covers both renderers, antialiasing,
# the pixel formats and textures (nearest and bilinear, small triangles and large, mip levels).
# Usage: tests/release/run.sh BUILD. One "ok NAME: ..." or "not ok NAME: why" line a frame.
set -u
build=${1:-build}
release="$build/maskline"
sanitized="$build/san/maskline"
work="$build/release-check"
rm -rf "$work" && mkdir -p "$work"
models=/usr/share/assimp/models/glTF2
box="$models/BoxTextured-glTF-Binary/BoxTextured.glb"
transform="$models/textureTransform/TextureTransformTest.gltf"
engine="$models/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"
# BoxTextured compiled nearest (by the release CLI; both CLIs read that blob): small nearest triangles.
box_nearest="$work/box-nearest.mls"
[ -f "$box" ] && "$release" compile "$box" -o "$box_nearest" --texture-filter nearest >/dev/null 2>&1

frames=(
  "bundled-tiler|--size 320x240"
  "bundled-scanline-aa3-gouraud|--renderer scanline --aa 3 --shading gouraud --size 160x120"
  "bundled-tiler-aa8-cosine-jittered|--aa 8 --filter cosine --samples jittered --size 96x72"
  "bundled-tiler-grey4|--format grey4 --size 128x64"
  "bundled-scanline-mono1|--renderer scanline --format mono1 --size 128x64"
  "banded-tiler|builtin:banded --size 320x240"
  "banded-small-tiler|builtin:banded --size 48x36"
  "banded-small-scanline|builtin:banded --renderer scanline --size 48x36"
  "boxtextured-tiler|$box --size 160x120"
  "boxtextured-scanline-aa2|$box --renderer scanline --aa 2 --size 160x120"
  "boxtextured-nearest-small-tiler|$box_nearest --size 48x36"
  "boxtextured-nearest-small-scanline|$box_nearest --renderer scanline --size 48x36"
  "texture-transform-scanline|$transform --renderer scanline --size 160x120"
  "engine-tiler|$engine --size 96x72"
)

for frame in "${frames[@]}"; do
  name=${frame%%|*}
  read -r -a opts <<<"${frame#*|}"
  for o in "${opts[@]}"; do  # a scene file the frame names
    if [[ $o == *.gl* || $o == *.mls ]] && [ ! -e "$o" ]; then echo "not ok release-$name: $o is missing"; continue 2; fi
  done
  if ! "$release" render "${opts[@]}" -o "$work/$name-release.png" >/dev/null 2>"$work/$name.err"; then
    echo "not ok release-$name: the release CLI failed: $(tail -1 "$work/$name.err")"
  elif ! "$sanitized" render "${opts[@]}" -o "$work/$name-sanitized.png" >/dev/null 2>"$work/$name.err"; then
    echo "not ok release-$name: the sanitized CLI failed: $(tail -1 "$work/$name.err")"
  elif cmp -s "$work/$name-release.png" "$work/$name-sanitized.png"; then
    echo "ok release-$name: -O2 and sanitized pictures identical ($(stat -c %s "$work/$name-release.png") bytes)"
  else
    echo "not ok release-$name: -O2 and sanitized pictures differ ($work/$name-release.png, $work/$name-sanitized.png)"
  fi
done
