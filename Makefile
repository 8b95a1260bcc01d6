# cohaptic: the two commands (see README.md).
#   make test   install missing packages, configure, build (Release), run every test
#   make demo   the same set-up, then the main job
#   make bench  the same set-up, then the benchmarks (BENCH_ARGS passes arguments through)
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
BENCH_ARGS ?=
SERVER := $(BUILD_DIR)/server/cohaptic-server

.PHONY: all deps configure build test demo bench clean

all: build

deps:
	@./deploy/install-deps.sh

$(BUILD_DIR)/CMakeCache.txt: | deps
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE)

configure: deps $(BUILD_DIR)/CMakeCache.txt

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	ctest --test-dir $(BUILD_DIR) --output-on-failure -j $(JOBS)

# Until the networked system exists, the main job is the probe on the paper's cube,
# through the intermediate representation: a tool pressed 1, 2, 5 and 10 mm into the
# front face's centre (one at a time); two tools pressing together; and the same two
# with the point-constraint model, 300 held boundary nodes (the paper's T300) and float32
# storage.
demo: build
	@$(SERVER) probe --scene scenes/cube.yaml --separately --tool 0,0,-1 --tool 0,0,-2 --tool 0,0,-5 --tool 0,0,-10
	@echo
	@$(SERVER) probe --scene scenes/cube.yaml --tool 30,-20,-5 --tool -60,60,-3 --log-level warn
	@echo
	@$(SERVER) probe --scene scenes/cube.yaml --tool 30,-20,-5 --tool -60,60,-3 --contact-model point \
	  --boundary-nodes 300 --ir-precision f32 --log-level warn

bench: build
	$(BUILD_DIR)/tests/cohaptic_bench $(BENCH_ARGS)

clean:
	rm -rf $(BUILD_DIR)
