# SPDX-License-Identifier: MIT
# Thin wrapper over CMake. `make` builds ./build/verdant.
BUILD ?= build
PREFIX ?= /usr/local
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
SANITIZE ?= 0
FUZZ_SECONDS ?= 30

ifeq ($(SANITIZE),1)
  BUILD := build-sanitize
  CMAKE_FLAGS += -DVD_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug
endif

.PHONY: all deps configure test bench demo install clean fuzz fuzz-smoke lint python

all: configure
	cmake --build $(BUILD) -j $(JOBS)

deps:
	@bash scripts/deps.sh

configure: deps
	@test -f $(BUILD)/CMakeCache.txt || cmake -S . -B $(BUILD) -DCMAKE_INSTALL_PREFIX=$(PREFIX) $(CMAKE_FLAGS) >/dev/null

# the Python package into $(BUILD)/python (PYTHONPATH=$(BUILD)/python /usr/bin/python3; docs/python.md)
python: configure
	cmake --build $(BUILD) -j $(JOBS) --target verdant_python verdant_python_files

test: all
	cd $(BUILD) && ctest -j $(JOBS) --output-on-failure

bench: all
	./$(BUILD)/verdant_bench $(BENCH_ARGS)
	./$(BUILD)/verdant_bench_render $(BENCH_ARGS)
	./$(BUILD)/verdant_bench_render_run $(BENCH_ARGS)
	bash bench/cloud_bench.sh ./$(BUILD)/verdant $(BENCH_ARGS)
	PYTHONPATH=$(BUILD)/python /usr/bin/python3 bench/python/cloud_bench.py $(BUILD) $(BENCH_ARGS)
	./$(BUILD)/verdant_bench_sim $(BENCH_ARGS)
	./$(BUILD)/verdant_bench_growth $(BENCH_ARGS)
	./$(BUILD)/verdant_bench_collide --csv bench/results/collide-2core.csv
	./$(BUILD)/verdant_bench_mujoco --csv bench/results/mujoco-chain-2core.csv
	./$(BUILD)/verdant_bench_harvest $(BENCH_ARGS)

demo: all
	@bash scripts/demo.sh ./$(BUILD)/verdant

install: configure
	cmake -S . -B $(BUILD) -DCMAKE_INSTALL_PREFIX=$(PREFIX) >/dev/null
	cmake --build $(BUILD) -j $(JOBS)
	cmake --install $(BUILD)

# libFuzzer targets built with clang into build-fuzz/, FUZZ_SECONDS each (fuzz/run.sh)
fuzz:
	@bash fuzz/run.sh $(FUZZ_SECONDS)

fuzz-smoke:
	@bash fuzz/run.sh 5

# static analysis: clang-tidy (.clang-tidy) and cppcheck over src/ and cli/; any finding fails
lint:
	@JOBS=$(JOBS) bash scripts/lint.sh

clean:
	rm -rf build build-sanitize build-lint python/build python/verdant.egg-info
