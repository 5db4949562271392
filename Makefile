# flexkin: two commands on a fresh Debian machine (they install what is missing themselves).
#   make demo   build, then run the paper's scenarios (figures' numbers printed, results in out/)
#   make test   build and run every test, then again under AddressSanitizer + UBSan, the
#               threaded ones under ThreadSanitizer, and the fuzz targets briefly (test-fuzz)
# Also: make bench (Google Benchmark, see docs/BENCHMARKS.md), make fuzz (libFuzzer, see
# docs/fuzzing.md), make install PREFIX=...

BUILD      ?= build
BUILD_SAN  ?= build-sanitize
BUILD_TSAN ?= build-tsan
BUILD_FUZZ ?= build-fuzz
FUZZ_SECONDS ?= 300
FUZZ_SHORT_SECONDS ?= 20
JOBS       ?= $(shell nproc)
PREFIX     ?= /usr/local
PYTHON     ?= /usr/bin/python3

# The C++ sources that clang-format keeps in the style of .clang-format (make format applies it).
FORMAT_FILES = $(shell git ls-files '*.cc' '*.h' 2>/dev/null)

.PHONY: all deps build demo test test-release test-sanitize test-thread test-fuzz fuzz fuzz-build bench install \
	blender-addon clean format format-check

all: build

deps:
	@bash scripts/install-deps.sh

build: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFLEXKIN_PYTHON=ON > /dev/null
	@cmake --build $(BUILD) -j$(JOBS)

demo: build
	@bash scripts/demo.sh $(BUILD)

test: test-release test-sanitize test-thread test-fuzz

test-release: build
	@ctest --test-dir $(BUILD) --output-on-failure -j$(JOBS)

# The sanitizer build links the libraries as shared objects (position-independent code): its test
# programs then hold their own code only, not each an instrumented copy of the library (140 MB
# each when linked statically). LeakSanitizer's options hook in src/render/canvas.cc is not read
# from a shared object, so its print_suppressions=0 is also given here (the command line's
# messages must stay one line).
test-sanitize: deps
	@cmake -S . -B $(BUILD_SAN) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFLEXKIN_SANITIZE=ON -DFLEXKIN_UNITY=ON \
	  -DBUILD_SHARED_LIBS=ON -DCMAKE_POSITION_INDEPENDENT_CODE=ON \
	  -DFLEXKIN_BUILD_BENCHMARKS=OFF -DFLEXKIN_BUILD_EXAMPLES=OFF > /dev/null
	@cmake --build $(BUILD_SAN) -j$(JOBS)
	@ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  LSAN_OPTIONS=print_suppressions=0 ctest --test-dir $(BUILD_SAN) --output-on-failure -j$(JOBS)

# The tests that run threads (the strand engine's worker pool, groom runs, the library called
# from several threads at once), under ThreadSanitizer: only their programs are built.
TSAN_TESTS = strands_test groom_run_test thread_safety_test
test-thread: deps
	@cmake -S . -B $(BUILD_TSAN) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFLEXKIN_SANITIZE_THREAD=ON -DFLEXKIN_UNITY=ON \
	  -DFLEXKIN_BUILD_APPS=OFF -DFLEXKIN_BUILD_BENCHMARKS=OFF -DFLEXKIN_BUILD_EXAMPLES=OFF \
	  -DFLEXKIN_PYTHON=OFF > /dev/null
	@cmake --build $(BUILD_TSAN) -j$(JOBS) --target $(TSAN_TESTS)
	@TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 \
	  ctest --test-dir $(BUILD_TSAN) --output-on-failure -j$(JOBS) \
	  -R '^($(shell echo $(TSAN_TESTS) | sed 's/ /|/g'))\.'

# The libFuzzer targets of fuzz/ (docs/fuzzing.md), built by clang with ASan + UBSan: only the
# libraries they link. `make fuzz` runs each for FUZZ_SECONDS on its seeds (new units kept in
# $(BUILD_FUZZ)/fuzz-run/); `make test-fuzz` for FUZZ_SHORT_SECONDS from the seeds alone, and
# fails if any target finds something.
fuzz-build: deps
	@CC=clang-14 CXX=clang++-14 cmake -S . -B $(BUILD_FUZZ) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFLEXKIN_FUZZ=ON -DFLEXKIN_UNITY=ON \
	  -DFLEXKIN_BUILD_APPS=OFF -DFLEXKIN_BUILD_TESTS=OFF -DFLEXKIN_BUILD_BENCHMARKS=OFF \
	  -DFLEXKIN_BUILD_EXAMPLES=OFF -DFLEXKIN_PYTHON=OFF > /dev/null
	@cmake --build $(BUILD_FUZZ) -j$(JOBS)

fuzz: fuzz-build
	@bash scripts/fuzz.sh $(BUILD_FUZZ) $(FUZZ_SECONDS)

test-fuzz: fuzz-build
	@bash scripts/fuzz.sh --fresh $(BUILD_FUZZ) $(FUZZ_SHORT_SECONDS)

bench: build
	@for b in propagation_benchmark scenes_benchmark overall_benchmark arm_benchmark arm_kdl_benchmark arm_limits_benchmark strands_benchmark urdf_kdl_benchmark mesh_colliders_benchmark snake_pegs_benchmark; do \
	  $(BUILD)/bench/$$b --benchmark_repetitions=5 --benchmark_report_aggregates_only=true || exit 1; \
	done
	@$(PYTHON) bench/python_benchmark.py --build $(BUILD)

format: deps
	@clang-format -i $(FORMAT_FILES)

# Fails, listing the places, if a C++ file is not formatted as clang-format would (.ci/run runs it).
format-check: deps
	@clang-format --dry-run --Werror $(FORMAT_FILES) && echo "format-check: $(words $(FORMAT_FILES)) files formatted"

install: build
	@cmake --install $(BUILD) --prefix $(PREFIX)

# The add-on for Blender (blender/addons/flexkin_blender, docs/blender.md) as the zip that Blender's
# Preferences > Add-ons > Install... takes.
blender-addon: build
	@rm -f $(BUILD)/flexkin_blender.zip
	@cd blender/addons && /usr/bin/python3 -m zipfile -c $(abspath $(BUILD))/flexkin_blender.zip flexkin_blender
	@echo "wrote $(BUILD)/flexkin_blender.zip"

clean:
	@rm -rf $(BUILD) $(BUILD_SAN) $(BUILD_TSAN) $(BUILD_FUZZ) out
