#!/usr/bin/env bash
# Times `extwrench estimate` on a 3.6 M-row log (1 h at 1 kHz, 7 joints + F/T reading + truth),
# CSV parsing, estimation, writing estimates.csv, metrics and figures included (issue 5,
# acceptance 3). The log (~1.7 GB) is generated once into OUT_DIR and reused.
#   usage: benchmarks/replay_long_log.sh BENCH_BUILD_DIR OUT_DIR [ROWS]
set -euo pipefail
build=$1
out=$2
rows=${3:-3600000}
mkdir -p "$out"
log="$out/log_${rows}.csv"
if [ ! -s "$log" ]; then
  echo "writing the $rows-row log $log ..."
  "$build/benchmarks/extwrench_make_log" "$rows" "$log.tmp"
  mv "$log.tmp" "$log"
fi
root=$(cd "$(dirname "$0")/.." && pwd)
printf 'robot: %s\nsensor: {type: ft}\n' "$root/models/paper_arm.urdf" > "$out/config.yaml"
rm -rf "$out/replay"
TIMEFORMAT="replay of $rows rows: %R s wall, %U s user, %S s system (target < 15 s wall)"
time "$build/extwrench" estimate --config "$out/config.yaml" --log "$log" --out "$out/replay"
