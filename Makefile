# Developer entry points. scripts/test.sh and scripts/demo.sh install the Debian packages first;
# these targets assume they are present (run `bash scripts/install_deps.sh` once).
JOBS ?= $(shell nproc)
BUILD ?= build
SANITIZE_BUILD ?= build-sanitize
BENCH_BUILD ?= build-release
RELEASE_BUILD ?= build-install
PREFIX ?= /usr/local
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 600
FUZZ_HARNESSES ?= urdf dh_yaml estimator_config scenario csv_log estimator calibration_file mjcf

.PHONY: all build test test-sanitize fuzz-build fuzz demo bench install format clean

all: build

# Debug information as line tables (-g1): backtraces, sanitizer reports and profiles keep their
# file:line, at a fraction of full -g's cost (which made the build 1.5-1.7x slower: 50 s instead
# of 30 s for src/estimation/contact_estimator.cpp). For gdb with variables, configure a build
# of your own with plain -g.
LINE_TABLES_RELWITHDEBINFO = -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG"

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo $(LINE_TABLES_RELWITHDEBINFO)

build: $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The tests under AddressSanitizer + UndefinedBehaviorSanitizer.
test-sanitize:
	cmake -S . -B $(SANITIZE_BUILD) -DCMAKE_BUILD_TYPE=Debug -DEXTWRENCH_SANITIZE=ON \
	  -DCMAKE_CXX_FLAGS="-O1" -DCMAKE_CXX_FLAGS_DEBUG="-g1" -DEXTWRENCH_BUILD_EXAMPLES=OFF
	cmake --build $(SANITIZE_BUILD) -j $(JOBS)
	cd $(SANITIZE_BUILD) && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ctest --output-on-failure -j $(JOBS)
	$(MAKE) fuzz-build
	cd $(FUZZ_BUILD) && ctest -L fuzz --output-on-failure -j $(JOBS)

# The libFuzzer harnesses of fuzz/ (clang, everything instrumented; docs/testing.md "Fuzzing").
fuzz-build:
	cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo $(LINE_TABLES_RELWITHDEBINFO) \
	  -DCMAKE_CXX_COMPILER=clang++ \
	  -DEXTWRENCH_BUILD_FUZZERS=ON -DEXTWRENCH_BUILD_TESTS=OFF -DEXTWRENCH_BUILD_CLI=OFF \
	  -DEXTWRENCH_BUILD_EXAMPLES=OFF
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target $(addprefix fuzz_,$(FUZZ_HARNESSES))

# Each harness fuzzed for FUZZ_SECONDS in turn (default 600 s); prints executions per harness.
fuzz: fuzz-build
	bash fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_SECONDS) $(FUZZ_HARNESSES)

# The main job builds only what it runs: the CLI (not the tests, benchmarks, examples).
demo: $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS) --target extwrench_cli
	$(BUILD)/extwrench simulate scenarios/paper.yaml --out results/paper

# A Release install (no debug information: sizes in README.md) of the libraries, headers, CLI
# and models into PREFIX; only the installed targets are built.
install:
	cmake -S . -B $(RELEASE_BUILD) -DCMAKE_BUILD_TYPE=Release -DEXTWRENCH_BUILD_TESTS=OFF \
	  -DEXTWRENCH_BUILD_EXAMPLES=OFF
	cmake --build $(RELEASE_BUILD) -j $(JOBS)
	cmake --install $(RELEASE_BUILD) --prefix $(PREFIX) --strip

bench:
	cmake -S . -B $(BENCH_BUILD) -DCMAKE_BUILD_TYPE=Release -DEXTWRENCH_BUILD_BENCHMARKS=ON \
	  -DEXTWRENCH_BUILD_TESTS=OFF
	cmake --build $(BENCH_BUILD) -j $(JOBS) --target extwrench_bench extwrench_cli extwrench_make_log
	mkdir -p $(BUILD)
	$(BENCH_BUILD)/benchmarks/extwrench_bench --benchmark_out=$(BUILD)/bench.json \
	  --benchmark_out_format=json --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
	python3 benchmarks/ratios.py $(BUILD)/bench.json
	bash benchmarks/replay_long_log.sh $(BENCH_BUILD) $(BUILD)/long_log

format:
	clang-format -i $$(git ls-files '*.hpp' '*.cpp')

clean:
	rm -rf $(BUILD) $(SANITIZE_BUILD) $(BENCH_BUILD) $(FUZZ_BUILD)
