#!/usr/bin/env bash
# make demo: renders the bundled scene with both renderers (and 2CylinderEngine when Debian's
# assimp-testmodels is installed) into out/, prints each frame's statistics, and says where the
# pictures are. Usage: tools/demo.sh BUILD
set -euo pipefail
build=${1:-build}
cli="$build/maskline"
out=out
mkdir -p "$out"
engine=/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb

render() {
  local label=$1
  shift
  echo "== $label"
  "$cli" render "$@" --stats
}

render "bundled scene, tiler (colour, ids, work image)" --size 640x480 \
  -o "$out/default-tiler.png" --ids "$out/default-tiler-ids.png" --work "$out/default-tiler-work.png"
render "bundled scene, scanline, 3x3 samples per pixel" --renderer scanline --aa 3 --size 640x480 \
  -o "$out/default-scanline-aa3.png"
if [ -f "$engine" ]; then
  render "2CylinderEngine, tiler" "$engine" --size 640x480 \
    -o "$out/engine-tiler.png" --ids "$out/engine-tiler-ids.png" --work "$out/engine-tiler-work.png"
  render "2CylinderEngine, scanline, 3x3 samples per pixel" "$engine" --renderer scanline --aa 3 --size 640x480 \
    -o "$out/engine-scanline-aa3.png"
else
  echo "== 2CylinderEngine skipped: $engine not installed (Debian package assimp-testmodels)"
fi
echo
echo "pictures in $(cd "$out" && pwd)/:"
ls -1 "$out"/*.png | sed 's/^/  /'
