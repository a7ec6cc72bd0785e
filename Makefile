# The README's two commands: `make demo` and `make test`. Both install what they need first.
BUILD ?= build
JOBS ?= $(shell nproc)
SANITIZE ?= 0

ifeq ($(SANITIZE),1)
BUILD := build-asan
CMAKE_FLAGS := -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSEMSEGMAP_SANITIZE=ON
else
CMAKE_FLAGS := -DCMAKE_BUILD_TYPE=Release
endif

.PHONY: setup build test demo bench fuzz format clean

setup:
	bash scripts/setup.sh

build: setup
	cmake -S . -B $(BUILD) $(CMAKE_FLAGS)
	cmake --build $(BUILD) -j $(JOBS)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# DEMO_ARGS: options of `semsegmap demo`, e.g. --preset tiny (CI: the same job on a smaller world).
DEMO_ARGS ?=
demo: build
	./$(BUILD)/semsegmap demo --out demo_out $(DEMO_ARGS)

bench: build
	./$(BUILD)/bench/semsegmap_bench

# The libFuzzer harnesses of the parsers (fuzz/): built by clang with ASan and UBSan into
# build-fuzz/, then each run for FUZZ_SECONDS from seeds the build generates. Skipped, saying
# why, when clang or its fuzzer runtime is missing.
FUZZ_SECONDS ?= 4
# FUZZ_TORCH=OFF (CI) builds without libtorch: the model-file harness then fuzzes the file
# format alone, not the network built from it.
FUZZ_TORCH ?= ON
# -O1 and line tables only, as libFuzzer advises: a crash's stack still names the lines, and the
# build takes a fraction of full debug information's time. FUZZ_OPT=-O0 (CI, a few seconds a
# harness) builds faster and runs each input slower.
FUZZ_OPT ?= -O1
FUZZ_CMAKE_FLAGS := -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$(FUZZ_OPT) -gline-tables-only -DNDEBUG" -DCMAKE_CXX_COMPILER=clang++ \
  -DSEMSEGMAP_FUZZ=ON -DSEMSEGMAP_WITH_SIM=OFF -DSEMSEGMAP_WITH_PYTHON=OFF \
  -DSEMSEGMAP_WITH_VIEWER=OFF -DSEMSEGMAP_BUILD_TESTS=OFF -DSEMSEGMAP_BUILD_BENCH=OFF \
  -DSEMSEGMAP_WITH_TORCH=$(FUZZ_TORCH)
fuzz: setup
	@if ! command -v clang++ > /dev/null; then \
	  echo "fuzz: skipped: clang++ is missing (scripts/setup.sh installs clang)"; \
	elif ! printf 'extern "C" int LLVMFuzzerTestOneInput(const char*, unsigned long) { return 0; }' \
	    | clang++ -x c++ -fsanitize=fuzzer - -o /dev/null 2> /dev/null; then \
	  echo "fuzz: skipped: clang cannot link -fsanitize=fuzzer (scripts/setup.sh installs libclang-rt-14-dev)"; \
	else \
	  cmake -S . -B build-fuzz $(FUZZ_CMAKE_FLAGS) && \
	  cmake --build build-fuzz -j $(JOBS) --target semsegmap_fuzzers && \
	  bash fuzz/run.sh build-fuzz $(FUZZ_SECONDS); \
	fi

format:
	find cpp apps tests bench fuzz python/src -name '*.cpp' -o -name '*.h' | xargs clang-format -i

clean:
	rm -rf build build-asan build-min build-fuzz
