#!/usr/bin/env bash
# Fuzzes the scene-blob reader and, on what it accepts, both renderers: tests/fuzz/run.sh BUILD SECONDS
# Seeds: the committed blobs in tests/fuzz/corpus/ plus, when BUILD/maskline (or make test's
# BUILD/san/maskline) exists, a few small assimp glTF models compiled with it, textured ones among
# them. Exits non-zero when the fuzzer finds a crash (or cannot run).
set -u
build=${1:-build}
seconds=${2:-60}
fuzzer="$build/fuzz_blob_reader"
here=$(cd "$(dirname "$0")" && pwd)

if [ ! -x "$fuzzer" ]; then
  make -s "$fuzzer" BUILD="$build" || { echo "fuzz: cannot build $fuzzer"; exit 1; }
fi

work="$build/fuzz"
corpus="$work/corpus"
mkdir -p "$corpus" "$work/artifacts"
cp "$here"/corpus/*.mls "$corpus"/ 2>/dev/null || true

models=/usr/share/assimp/models/glTF2
compiler="$build/maskline"
[ -x "$compiler" ] || compiler="$build/san/maskline"
if [ -x "$compiler" ] && [ -d "$models" ]; then
  for m in BoxTextured-glTF-Binary/BoxTextured.glb glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_13.gltf \
           simple_skin/simple_skin.gltf textureTransform/TextureTransformTest.gltf; do
    [ -f "$models/$m" ] || continue
    out="$corpus/$(basename "${m%.*}").mls"
    [ -f "$out" ] || "$compiler" compile "$models/$m" -o "$out" >/dev/null 2>&1 || rm -f "$out"
  done
fi

seeds=$(ls "$corpus" | wc -l)
echo "fuzz: $seeds seed(s), $seconds s"
"$fuzzer" -max_total_time="$seconds" -max_len=65536 -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix="$work/artifacts/" -print_final_stats=1 "$corpus" 2>"$work/log.txt"
rc=$?
tail -n 12 "$work/log.txt"
if [ "$rc" -ne 0 ]; then
  echo "fuzz: FAILED (exit $rc); reproducer(s) in $work/artifacts/, log in $work/log.txt"
  exit 1
fi
echo "fuzz: ok"
