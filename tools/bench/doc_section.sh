#!/usr/bin/env bash
# Writes one generated section of DOC (default docs/benchmarks.md), replacing the lines between its
# markers <!-- NAME:begin ... --> and <!-- NAME:end --> (both included in SECTION), or appending it
# under HEADING when the file has none yet. Sourced by the bench scripts.
# Usage: write_doc_section NAME HEADING SECTION [DOC]
write_doc_section() {
  local name=$1 heading=$2 section=$3 doc=${4:-docs/benchmarks.md}
  mkdir -p docs
  [ -f "$doc" ] || printf '# Benchmarks\n' >"$doc"
  if grep -q "<!-- $name:begin" "$doc"; then
    NAME="$name" SECTION="$section" awk '
      index($0, "<!-- " ENVIRON["NAME"] ":begin") == 1 { print ENVIRON["SECTION"]; skip = 1; next }
      index($0, "<!-- " ENVIRON["NAME"] ":end -->") == 1 { skip = 0; next }
      !skip { print }' "$doc" >"$doc.tmp" && mv "$doc.tmp" "$doc"
  else
    printf '\n## %s\n\n%s\n' "$heading" "$section" >>"$doc"
  fi
}
