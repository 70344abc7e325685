#!/usr/bin/env bash
# make demo: renders the bundled scene with both renderers (and 2CylinderEngine and the textured
# BoxTextured when Debian's assimp-testmodels is installed, and the textured banded scene) into out/, prints each frame's statistics, and says where the
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
render "bundled scene, tiler, 8x8 samples per pixel (box filter)" --aa 8 --size 640x480 \
  -o "$out/default-tiler-aa8.png"
render "bundled scene, tiler, 8x8 jittered samples per pixel (cosine-hump filter)" --aa 8 --filter cosine \
  --samples jittered --size 640x480 -o "$out/default-tiler-aa8-cosine.png"
# Point-sampled beside antialiased (box, then cosine-hump on jittered samples), a detail enlarged 4 times.
"$build/side_by_side" "$out/default-tiler-vs-aa8.png" --crop 240,180,160,120 --zoom 4 \
  "$out/default-tiler.png" "$out/default-tiler-aa8.png" "$out/default-tiler-aa8-cosine.png"
echo "== point-sampled (left), 8x8 box-filtered (middle) and 8x8 jittered cosine-hump-filtered (right) tiler, detail 4x: $out/default-tiler-vs-aa8.png"
if [ -f "$engine" ]; then
  render "2CylinderEngine, tiler" "$engine" --size 640x480 \
    -o "$out/engine-tiler.png" --ids "$out/engine-tiler-ids.png" --work "$out/engine-tiler-work.png"
  render "2CylinderEngine, scanline, 3x3 samples per pixel" "$engine" --renderer scanline --aa 3 --size 640x480 \
    -o "$out/engine-scanline-aa3.png"
else
  echo "== 2CylinderEngine skipped: $engine not installed (Debian package assimp-testmodels)"
fi

# Textures (docs/textures.md): a textured model, and the banded scene whose four textures the pager
# loads when their first row is reached and frees after their last.
boxtex=/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb
if [ -f "$boxtex" ]; then
  render "BoxTextured (textured model), tiler" "$boxtex" --size 640x480 -o "$out/boxtextured-tiler.png"
  render "BoxTextured, scanline, 3x3 samples per pixel" "$boxtex" --renderer scanline --aa 3 --size 640x480 \
    -o "$out/boxtextured-scanline-aa3.png"
else
  echo "== BoxTextured skipped: $boxtex not installed (Debian package assimp-testmodels)"
fi
render "banded scene (four textures, lazy pager), scanline" builtin:banded --renderer scanline --size 640x480 \
  --eye 0.4,0.3,5.6 --target 0,0,0 -o "$out/banded-scanline.png"
render "banded scene, scanline, texture pool of the largest texture only (same image, reloads)" builtin:banded \
  --renderer scanline --size 640x480 --eye 0.4,0.3,5.6 --target 0,0,0 --texture-pool 8208 -o "$out/banded-small-pool.png"

# The emulated panels decode the exact bytes each panel would receive on its bus.
show() {
  local label=$1
  shift
  echo "== $label"
  "$cli" show "$@" --stats
}
show "bundled scene on an emulated ILI9341 (320x240 landscape, RGB565 over SPI)" --display emu:ili9341 \
  --size 320x240 -o "$out/panel-ili9341.png"
show "bundled scene on an emulated SSD0323 OLED (128x64, 4-bit grey, dithered), shown 4x" --display emu:ssd0323 \
  --zoom 4 -o "$out/panel-ssd0323.png"
show "bundled scene on an emulated SSD1306 OLED (128x64, 1 bit, dithered), shown 4x" --display emu:ssd1306 \
  --background 000000 --zoom 4 -o "$out/panel-ssd1306.png"
if [ -f "$engine" ]; then
  show "2CylinderEngine on an emulated ST7789 (240x240), scanline 3x3" "$engine" --display emu:st7789-240 \
    --renderer scanline --aa 3 -o "$out/panel-st7789-engine.png"
fi
echo "== the bundled scene turning on the emulated ILI9341 (12 frames, 30 degrees a frame)"
"$cli" show --display emu:ili9341 --size 320x240 --frames 12 --orbit 30 -o "$out/orbit-%02d.png" | tail -2

echo
echo "pictures in $(cd "$out" && pwd)/:"
ls -1 "$out"/*.png | sed 's/^/  /'
