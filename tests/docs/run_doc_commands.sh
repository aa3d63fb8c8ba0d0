#!/usr/bin/env bash
# Every command shown in README.md and docs/*.md is run, so that none rots (issue 11). The
# commands are extracted from the fenced blocks (and 4-space indented lines) that start with
# `extwrench` or `build/extwrench`, in the order of the files, and run with the built binary
# in a scratch directory holding the repository's models/ and scenarios/, a states.csv for
# `dynamics`, and arm.urdf (the paper arm). The documents' placeholders are filled in: DIR
# (a scenario's output: results/paper/seed_1), OTHER, COMMAND (each command). `make ...` and
# `bash scripts/...` lines build and install: they are listed as not run here (CI runs
# scripts/test.sh, and `make demo` is the simulate line above it).
#
# Usage: tests/docs/run_doc_commands.sh SOURCE_DIR EXTWRENCH_BINARY
set -uo pipefail
src=$(cd "$1" && pwd)
bin=$(readlink -f "$2")
work=$(mktemp -d "${TMPDIR:-/tmp}/extwrench_docs.XXXXXX")
trap 'rm -rf "$work"' EXIT
cd "$work"
ln -s "$src/models" models
ln -s "$src/scenarios" scenarios
cp "$src/models/paper_arm.urdf" arm.urdf
# States of the paper arm (7 joints) for `dynamics`: t, q, dq, ddq.
{
  printf 't'
  for v in q dq ddq; do for i in 1 2 3 4 5 6 7; do printf ',%s%d' "$v" "$i"; done; done
  printf '\n'
  for k in 0 1 2 3 4; do
    printf '%s' "0.00$k"
    for i in $(seq 1 21); do printf ',0.%d' $(( (i * 7 + k) % 10 )); done
    printf '\n'
  done
} > states.csv

commands() {  # file -> the documented commands, one per line
  awk '
    /^```/ { fence = !fence; next }
    {
      line = $0
      if (!fence && line !~ /^    /) next
      sub(/^ +/, "", line)
      if (line !~ /^(build\/)?extwrench( |$)/) next
      sub(/ +#.*$/, "", line)      # a trailing comment
      sub(/   +[^-"].*$/, "", line) # an aligned description ("extwrench --help   commands")
      print line
    }' "$1"
}

fail=0; ran=0
for doc in "$src/README.md" "$src"/docs/*.md; do
  while IFS= read -r cmd; do
    [ -n "$cmd" ] || continue
    run=${cmd#build/}
    run=${run#extwrench}
    run=${run//DIR/results/paper/seed_1}
    run=${run//OTHER/results/other}
    run=${run//COMMAND/info}
    ran=$((ran + 1))
    if eval "\"$bin\"$run" > out.txt 2> err.txt; then
      echo "ok   ${doc#$src/}: $cmd"
    else
      echo "FAIL ${doc#$src/}: $cmd"; sed 's/^/     /' err.txt | tail -5; fail=1
    fi
  done < <(commands "$doc")
  grep -nE '^(make |bash scripts/)' "$doc" /dev/null 2>/dev/null | sed "s#^$src/#not run here (builds/installs): #"
done
echo "doc commands: $ran run"
[ "$ran" -gt 0 ] || { echo "no commands found"; exit 1; }
exit $fail
