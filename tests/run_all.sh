#!/usr/bin/env bash
# Runs every test: the sanitized GoogleTest binary (unit, property, oracle and CLI tests), the fuzz
# smoke runs of the blob reader and of the glTF importer, the release CLI's pictures against the
# sanitized CLI's (tests/release), the framebuffer test under QEMU (tests/qemu-fbdev) and the
# firmware checks under qemu-system-arm (tests/firmware).
# Usage: tests/run_all.sh BUILD MASK_K
# The last line is exactly "N passed, N failed"; the exit status is non-zero when anything failed.
set -u

build=${1:-build}
mask_k=${2:-16}
export MASKLINE_CLI="$build/san/maskline"
export MASKLINE_MASKGEN="$build/maskgen"
export MASKLINE_MASK_K="$mask_k"

passed=0
failed=0
failures=()
log="$build/test-log.txt"
: >"$log"

# ---- GoogleTest binary ------------------------------------------------------------------------
tests_bin="$build/san/tests"
if [ -x "$tests_bin" ]; then
  echo "tests: running $tests_bin (full log: $log)"
  start=$SECONDS
  "$tests_bin" --gtest_color=no >>"$log" 2>&1
  rc=$?
  # A test passed when gtest printed "[       OK ] Name (N ms)", failed on "[  FAILED  ] Name (N ms)".
  # A test that started but never finished (the binary crashed inside it) counts as failed.
  summary=$(awk '
    /^\[ RUN      \] / { running = $4; next }
    /^\[       OK \] .*\([0-9]+ ms\)$/ { ok++; running = ""; next }
    /^\[  FAILED  \] .*\([0-9]+ ms\)$/ { bad++; name = $4; sub(/,$/, "", name); print "FAIL " name; running = ""; next }
    END { if (running != "") { bad++; print "FAIL " running " (crashed)" } print "COUNT " ok + 0 " " bad + 0 }
  ' "$log")
  read -r _ ok bad <<<"$(grep '^COUNT ' <<<"$summary")"
  while IFS= read -r line; do failures+=("${line#FAIL }"); done < <(grep '^FAIL ' <<<"$summary")
  passed=$((passed + ok))
  failed=$((failed + bad))
  if [ "$rc" -ne 0 ] && [ "$bad" -eq 0 ]; then
    failed=$((failed + 1))
    failures+=("$tests_bin exited with status $rc")
  fi
  echo "tests: $ok passed, $bad failed in $((SECONDS - start)) s"
else
  failed=$((failed + 1))
  failures+=("$tests_bin is missing")
fi

# ---- fuzz smoke (one test) --------------------------------------------------------------------
if [ -f tests/fuzz/run.sh ]; then
  echo "fuzz: 10 s smoke run of the blob reader"
  if bash tests/fuzz/run.sh "$build" 10 >>"$log" 2>&1; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    failures+=("fuzz smoke (tests/fuzz/run.sh $build 10)")
  fi
else
  failed=$((failed + 1))
  failures+=("fuzz smoke: tests/fuzz/run.sh is missing")
fi

# ---- glTF fuzz smoke (one test) ------------------------------------------------------------------
if [ -f tests/fuzz/run_gltf.sh ]; then
  echo "fuzz: 15 s smoke run of the glTF importer, compiler and renderers"
  if bash tests/fuzz/run_gltf.sh "$build" 15 >>"$log" 2>&1; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    failures+=("glTF fuzz smoke (tests/fuzz/run_gltf.sh $build 15)")
  fi
else
  failed=$((failed + 1))
  failures+=("glTF fuzz smoke: tests/fuzz/run_gltf.sh is missing")
fi

# ---- scripts of checks, one test per "ok NAME: ..." / "not ok NAME: why" line they print ----------
# run_checks LABEL SCRIPT WHAT
run_checks() {
  local label=$1 script=$2 what=$3 start=$SECONDS line
  if [ ! -f "$script" ]; then
    failed=$((failed + 1))
    failures+=("$label: $script is missing")
    return
  fi
  echo "$label: $what"
  while IFS= read -r line; do
    echo "$line" >>"$log"
    case "$line" in
      "ok "*) passed=$((passed + 1)); echo "$label: ${line#ok }" ;;
      "not ok "*) failed=$((failed + 1)); failures+=("$label ${line#not ok }") ;;
    esac
  done < <(bash "$script" "$build" 2>>"$log")
  echo "$label: done in $((SECONDS - start)) s"
}
run_checks release tests/release/run.sh "the -O2 CLI's pictures against the sanitized CLI's"
run_checks qemu-fbdev tests/qemu-fbdev/run.sh "the fbdev sink on a real kernel's /dev/fb0 under QEMU"
run_checks firmware tests/firmware/run.sh "Cortex-M boards under qemu-system-arm against the host's frames"

if [ ${#failures[@]} -gt 0 ]; then
  echo "failed:"
  for f in "${failures[@]}"; do echo "  $f"; done
fi
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
