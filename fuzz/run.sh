#!/usr/bin/env bash
# `make fuzz`: fuzz each harness in turn for a set time and print what it did.
#   bash fuzz/run.sh BUILD_DIR SECONDS HARNESS...
# Each harness grows its corpus in BUILD_DIR/fuzz/corpus/HARNESS (kept between runs) from the
# seeds CMake gathered in BUILD_DIR/fuzz/seeds/HARNESS; its log is BUILD_DIR/fuzz/logs/HARNESS.log
# and any finding (crash, sanitizer report, leak, timeout of 25 s, over 2 GB) is saved in
# BUILD_DIR/fuzz/findings/HARNESS/. Exits 1 when a harness has a finding.
set -uo pipefail
build=$1 seconds=$2
shift 2
dir=$build/fuzz
mkdir -p "$dir/logs"
status=0
summary=()
for harness in "$@"; do
  mkdir -p "$dir/corpus/$harness" "$dir/findings/$harness"
  log=$dir/logs/$harness.log
  echo "fuzz_$harness: fuzzing for $seconds s (log: $log)"
  "$dir/fuzz_$harness" -max_total_time="$seconds" -timeout=25 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$dir/findings/$harness/" \
    "$dir/corpus/$harness" "$dir/seeds/$harness" >"$log" 2>&1
  rc=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  time=$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$log" | tail -1)
  corpus=$(find "$dir/corpus/$harness" -type f | wc -l)
  findings=$(find "$dir/findings/$harness" -type f | wc -l)
  if [ "$rc" != 0 ] || [ "$findings" != 0 ]; then
    status=1
    grep -m3 -E 'ERROR|==[0-9]+==|fuzz_' "$log" | sed 's/^/    /'
  fi
  line="fuzz_$harness: ${runs:-?} executions in ${time:-?} s, corpus $corpus inputs,"
  line+=" $findings findings (exit $rc)"
  summary+=("$line")
  echo "$line"
done
echo "---- summary"
printf '%s\n' "${summary[@]}"
exit "$status"
