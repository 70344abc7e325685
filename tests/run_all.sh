#!/usr/bin/env bash
# Runs every test: the sanitized GoogleTest binary (unit, property, oracle and CLI tests), the fuzz
# smoke runs of the blob reader and of the glTF importer, the framebuffer test under QEMU
# (tests/qemu-fbdev) and the firmware checks under qemu-system-arm (tests/firmware).
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

# ---- QEMU framebuffer test (one test per screen configuration) ---------------------------------
if [ -f tests/qemu-fbdev/run.sh ]; then
  echo "qemu-fbdev: the fbdev sink on a real kernel's /dev/fb0 under QEMU"
  start=$SECONDS
  while IFS= read -r line; do
    echo "$line" >>"$log"
    case "$line" in
      "ok "*) passed=$((passed + 1)); echo "qemu-fbdev: ${line#ok }" ;;
      "not ok "*) failed=$((failed + 1)); failures+=("qemu-fbdev ${line#not ok }") ;;
    esac
  done < <(bash tests/qemu-fbdev/run.sh "$build" 2>>"$log")
  echo "qemu-fbdev: done in $((SECONDS - start)) s"
else
  failed=$((failed + 1))
  failures+=("qemu-fbdev: tests/qemu-fbdev/run.sh is missing")
fi

# ---- firmware under QEMU (one test per check: tests/firmware/run.sh) ----------------------------
if [ -f tests/firmware/run.sh ]; then
  echo "firmware: Cortex-M boards under qemu-system-arm against the host's frames"
  start=$SECONDS
  while IFS= read -r line; do
    echo "$line" >>"$log"
    case "$line" in
      "ok "*) passed=$((passed + 1)); echo "firmware: ${line#ok }" ;;
      "not ok "*) failed=$((failed + 1)); failures+=("firmware ${line#not ok }") ;;
    esac
  done < <(bash tests/firmware/run.sh "$build" 2>>"$log")
  echo "firmware: done in $((SECONDS - start)) s"
else
  failed=$((failed + 1))
  failures+=("firmware: tests/firmware/run.sh is missing")
fi

if [ ${#failures[@]} -gt 0 ]; then
  echo "failed:"
  for f in "${failures[@]}"; do echo "  $f"; done
fi
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
