#!/usr/bin/env bash
# Times `extwrench estimate` over 8 logs of 450 000 rows (7.5 min at 1 kHz each, 7 joints + F/T
# reading + truth), serially (--jobs 1) and two at a time (--jobs 2), and prints both times and
# their ratio (issue 15, acceptance 3: <= 0.6 on a 2-core machine), with the serial run's CPU
# time: on C cores --jobs cannot beat (serial CPU time) / C, printed as the bound. --jobs N is N
# cores: with 8 logs, --jobs 1 and 2 run each replay on one thread (no reader or writer thread).
# The outputs of both runs must be the same bytes.
# The logs (~220 MB each) are written once into OUT_DIR and reused.
#   usage: benchmarks/replay_many_logs.sh BENCH_BUILD_DIR OUT_DIR [ROWS] [LOGS]
set -euo pipefail
build=$1
out=$2
rows=${3:-450000}
count=${4:-8}
mkdir -p "$out/logs"
for i in $(seq 1 "$count"); do
  log="$out/logs/log_${i}_${rows}.csv"
  if [ ! -s "$log" ]; then
    echo "writing the $rows-row log $log ..."
    "$build/benchmarks/extwrench_make_log" "$rows" "$log.tmp"
    mv "$log.tmp" "$log"
  fi
done
root=$(cd "$(dirname "$0")/.." && pwd)
printf 'robot: %s\nsensor: {type: ft}\n' "$root/models/paper_arm.urdf" > "$out/config.yaml"
cores=$(nproc)
run() {  # $1 = jobs; prints "wall user+sys"
  rm -rf "$out/jobs_$1"
  local start end
  start=$(date +%s.%N)
  /usr/bin/time -f "%U %S" -o "$out/time_$1.txt" "$build/extwrench" estimate --no-figures \
    --config "$out/config.yaml" --log "$out/logs/log_*_${rows}.csv" --out "$out/jobs_$1" \
    --jobs "$1" > "$out/jobs_$1.out" 2>&1
  end=$(date +%s.%N)
  echo "$(echo "$end - $start" | bc -l) $(awk '{print $1 + $2}' "$out/time_$1.txt")"
}
read -r serial serial_cpu < <(run 1)
read -r parallel parallel_cpu < <(run 2)
diff -r "$out/jobs_1" "$out/jobs_2" > /dev/null 2>&1 &&
  echo "outputs of --jobs 1 and --jobs 2: the same bytes" ||
  { echo "outputs of --jobs 1 and --jobs 2 DIFFER"; exit 1; }
# metrics.json names the log, not the output directory: the comparison above is byte for byte.
awk -v s="$serial" -v p="$parallel" -v sc="$serial_cpu" -v pc="$parallel_cpu" -v c="$cores" \
  -v n="$count" -v r="$rows" 'BEGIN {
  printf "%d logs of %d rows: --jobs 1 %.2f s wall (%.2f s CPU), --jobs 2 %.2f s wall (%.2f s CPU)\n", n, r, s, sc, p, pc
  printf "ratio --jobs 2 / --jobs 1: %.3f (target <= 0.6); bound on %d cores: CPU / cores / wall = %.3f\n", p / s, c, sc / c / s
}'
