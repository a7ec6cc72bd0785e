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

.PHONY: setup build test demo bench format clean

setup:
	bash scripts/setup.sh

build: setup
	cmake -S . -B $(BUILD) $(CMAKE_FLAGS)
	cmake --build $(BUILD) -j $(JOBS)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

demo: build
	./$(BUILD)/semsegmap demo --out demo_out

bench: build
	./$(BUILD)/bench/semsegmap_bench

format:
	find cpp apps tests bench python/src -name '*.cpp' -o -name '*.h' | xargs clang-format -i

clean:
	rm -rf build build-asan build-min
