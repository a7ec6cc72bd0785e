#!/usr/bin/env bash
# Runs every harness of a fuzz build for SECONDS each (default 4) from its generated seeds, with
# libFuzzer's limits: an input that takes more than 10 s, or more than 2 GB, is a finding like a
# crash. Findings go to findings/<harness>/ of the build folder and fail the run; the corpus
# each run grows is kept in corpus/<harness>/ for the next. Usage: run.sh BUILD_DIR [SECONDS]
# [HARNESS...]
set -euo pipefail
build="$1"
seconds="${2:-4}"
shift $(( $# >= 2 ? 2 : $# ))
fuzz="$build/fuzz"
read -r -a harnesses <<< "$(tr ';' ' ' < "$fuzz/harnesses.txt")"
[ $# -gt 0 ] && harnesses=("$@")
failed=()
for h in "${harnesses[@]}"; do
  corpus="$fuzz/corpus/$h" findings="$fuzz/findings/$h"
  mkdir -p "$corpus" "$findings"
  if ! "$fuzz/fuzz_$h" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 \
      -print_final_stats=1 -artifact_prefix="$findings/" "$corpus" "$fuzz/corpus_seeds/$h" \
      > "$fuzz/$h.log" 2>&1; then
    failed+=("$h")
    echo "fuzz: $h FOUND SOMETHING (log $fuzz/$h.log, input in $findings/)"
  else
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$fuzz/$h.log" | grep -o '[0-9]*$')
    echo "fuzz: $h ok, ${runs:-?} runs in ${seconds} s"
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: findings in ${failed[*]}"
  exit 1
fi
