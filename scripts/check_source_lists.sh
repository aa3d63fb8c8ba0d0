#!/usr/bin/env bash
# Every source on disk is named in a CMake list (the lists are explicit, issue 8): a file added
# without its line in CMakeLists.txt would otherwise silently not be built. Run from anywhere.
set -euo pipefail
cd "$(dirname "$0")/.."
missing=0
check() {  # $1 = file, $2 = the CMakeLists.txt that must list it, $3 = the name it is listed by
  if ! grep -Eq "^[[:space:]]*$3([[:space:])]|\$)" "$2"; then
    echo "not in $2: $1"
    missing=1
  fi
}
while IFS= read -r f; do check "$f" CMakeLists.txt "$f"; done \
  < <(find src cli examples -name '*.cpp' | sort)
while IFS= read -r f; do check "$f" bridges/mujoco/CMakeLists.txt "${f#bridges/mujoco/}"; done \
  < <(find bridges/mujoco -name '*.cpp' 2>/dev/null | sort)
while IFS= read -r f; do check "$f" python/CMakeLists.txt "${f#python/}"; done \
  < <(find python -maxdepth 1 -name '*.[ch]pp' 2>/dev/null | sort)
while IFS= read -r f; do check "$f" benchmarks/CMakeLists.txt "${f#benchmarks/}"; done \
  < <(find benchmarks -maxdepth 1 -name '*.cpp' | sort)
while IFS= read -r f; do
  rel=${f#tests/}
  dir=${rel%%/*}
  # The file must sit in its own folder's list: extwrench_add_test_dir(<dir> ... <file> ...).
  if ! awk -v d="$dir" -v n="${rel#*/}" '
      $0 ~ "^extwrench_add_test_dir\\(" d "$" { inside = 1; next }
      inside && $1 ~ "^" n "\\)?$" { found = 1 }
      inside && /\)/ { inside = 0 }
      END { exit !found }' tests/CMakeLists.txt; then
    echo "not in tests/CMakeLists.txt under $dir: $f"
    missing=1
  fi
done < <(find tests -name 'test_*.cpp' -not -path 'tests/packaging/*' | sort)
# fuzz/fuzz_<name>.cpp: <name> in the harness list of fuzz/CMakeLists.txt.
for f in $(find fuzz -name 'fuzz_*.cpp' 2>/dev/null | sort); do
  n=$(basename "$f" .cpp)
  if ! grep -Eq "^foreach\(harness .*\b${n#fuzz_}\b" fuzz/CMakeLists.txt; then
    echo "not in fuzz/CMakeLists.txt: $f"
    missing=1
  fi
done
for f in $(find tests/support -name '*.cpp' | sort); do check "$f" tests/CMakeLists.txt ".*${f#tests/}"; done
if [ "$missing" = 0 ]; then echo "check_source_lists: every source is listed"; fi
exit "$missing"
