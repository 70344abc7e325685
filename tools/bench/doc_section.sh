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

# ratio A B [DECIMALS]: A / B with two decimals (or DECIMALS: a target's verdict reads three), or "n/a"
ratio() {
  if [ -n "${1:-}" ] && [ -n "${2:-}" ] && [ "$2" != 0 ]; then
    awk -v a="$1" -v b="$2" -v d="${3:-2}" 'BEGIN { printf "%.*f", d, a / b }'
  else
    echo n/a
  fi
}

# A targets table under TITLE, its rows made by target_row. Prints the lines.
# Usage: targets_table TITLE ROW...
targets_table() {
  printf '%s\n' "" "$1" "" "| target | goal | measured | |" "|---|---:|---:|---|"
  shift
  printf '%s\n' "$@"
}

# One row of a targets table: | LABEL | <= GOAL | MEASURED | met, missed or not measured |, for a
# target that MEASURED must not exceed. Prints the row.
# Usage: target_row LABEL MEASURED GOAL
target_row() {
  local label=$1 measured=${2:-} goal=$3 verdict
  if [ -z "$measured" ] || [ "$measured" = n/a ]; then
    verdict="not measured"; measured="—"
  elif awk -v m="$measured" -v g="$goal" 'BEGIN { exit !(m + 0 <= g + 0) }'; then
    verdict=met
  else
    verdict=missed
  fi
  printf '| %s | ≤ %s | %s | %s |\n' "$label" "$goal" "$measured" "$verdict"
}
