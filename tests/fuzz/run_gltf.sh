#!/usr/bin/env bash
# Fuzzes the glTF importer, the compiler and both renderers: tests/fuzz/run_gltf.sh BUILD SECONDS [MAX_LEN]
# MAX_LEN (default 65536) caps input size; longer seeds are cut to it (larger values reach the big
# models but run far fewer executions per second).
# Seeds, copied at run time: every .gltf/.glb under /usr/share/assimp/models/glTF2 (a .gltf's external
# buffers embedded as data: URIs, since the fuzz target reads no file) and the committed regression
# inputs in tests/fuzz/gltf_regressions/. The corpus grows in BUILD/fuzz-gltf/corpus between runs.
# Exits non-zero when the fuzzer finds a crash, a hang or a big allocation (or cannot run).
set -u
build=${1:-build}
seconds=${2:-60}
max_len=${3:-65536}
fuzzer="$build/fuzz_gltf_import"
here=$(cd "$(dirname "$0")" && pwd)

if [ ! -x "$fuzzer" ]; then
  make -s "$fuzzer" BUILD="$build" || { echo "fuzz-gltf: cannot build $fuzzer"; exit 1; }
fi

work="$build/fuzz-gltf"
seeds="$work/seeds"
corpus="$work/corpus"
mkdir -p "$seeds" "$corpus" "$work/artifacts"
cp "$here"/gltf_regressions/* "$seeds"/ 2>/dev/null || true

models=/usr/share/assimp/models/glTF2
if [ -d "$models" ] && [ ! -f "$seeds/.assimp-done" ]; then
  python3 - "$models" "$seeds" <<'EOF'
import base64, json, os, shutil, sys
models, out = sys.argv[1], sys.argv[2]
n = 0
for root, _, files in os.walk(models):
    for name in sorted(files):
        path = os.path.join(root, name)
        ext = os.path.splitext(name)[1].lower()
        if ext not in ('.gltf', '.glb'):
            continue
        n += 1
        dest = os.path.join(out, 'assimp-%02d-%s' % (n, name))
        if ext == '.glb':
            shutil.copyfile(path, dest)
            continue
        try:
            with open(path, 'rb') as f:
                doc = json.loads(f.read())
            for b in doc.get('buffers', []):
                uri = b.get('uri', '')
                if uri and not uri.startswith('data:'):
                    with open(os.path.join(root, uri), 'rb') as f:
                        b['uri'] = 'data:application/octet-stream;base64,' + base64.b64encode(f.read()).decode()
            with open(dest, 'w') as f:
                json.dump(doc, f, separators=(',', ':'))
        except Exception:
            shutil.copyfile(path, dest)   # broken on purpose (or unreadable): keep it as it is
EOF
  touch "$seeds/.assimp-done"
fi

echo "fuzz-gltf: $(ls "$seeds" | wc -l) seed(s), $(ls "$corpus" | wc -l) corpus file(s), $seconds s"
"$fuzzer" -max_total_time="$seconds" -max_len="$max_len" -timeout=20 -dict="$here/gltf.dict" -rss_limit_mb=2048 -malloc_limit_mb=1024 \
  -artifact_prefix="$work/artifacts/" -print_final_stats=1 "$corpus" "$seeds" 2>"$work/log.txt"
rc=$?
tail -n 14 "$work/log.txt"
if [ "$rc" -ne 0 ]; then
  echo "fuzz-gltf: FAILED (exit $rc); reproducer(s) in $work/artifacts/, log in $work/log.txt"
  exit 1
fi
echo "fuzz-gltf: ok"
