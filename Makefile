# cohaptic: the two commands (see README.md).
#   make test   install missing packages, configure, build (Release), run every test
#   make demo   the same set-up, then the main job
#   make tradeoff  the same set-up, then the speed/accuracy grid on the cube
#   make bench  the same set-up, then the benchmarks (BENCH_ARGS passes arguments through)
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
BENCH_ARGS ?=
# Extra CMake settings for the first configure, e.g. CMAKE_ARGS=-DCOHAPTIC_WARNINGS_AS_ERRORS=ON (CI).
CMAKE_ARGS ?=
LAB := $(BUILD_DIR)/lab/cohaptic-lab

.PHONY: all deps configure build test demo probe-demo tradeoff bench clean

all: build

deps:
	@./deploy/install-deps.sh

$(BUILD_DIR)/CMakeCache.txt: | deps
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) $(CMAKE_ARGS)

configure: deps $(BUILD_DIR)/CMakeCache.txt

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	ctest --test-dir $(BUILD_DIR) --output-on-failure -j $(JOBS)

# The main job: the two-surgeon brain demo. A server and two haptic clients (hand models
# following the surgeons' scripted motions) on loopback, P1, about 20 s; prints a summary
# table, writes out/demo/report.json, and fails if the session was unhealthy.
demo: build
	@BUILD_DIR=$(BUILD_DIR) ./deploy/run-demo.sh

# The probe on the paper's cube, through the intermediate representation: a tool pressed
# 1, 2, 5 and 10 mm into the front face's centre, then two tools together.
probe-demo: build
	@$(LAB) probe --scene scenes/cube.yaml --separately --tool 0,0,-1 --tool 0,0,-2 --tool 0,0,-5 --tool 0,0,-10
	@echo
	@$(LAB) probe --scene scenes/cube.yaml --tool 30,-20,-5 --tool -60,60,-3 --contact-model point \
	  --boundary-nodes 300 --ir-precision f32 --log-level warn

# Speed against accuracy on the paper's cube (README "Speed versus accuracy"): every
# setting against the full solve on an 18-division mesh; about a minute.
tradeoff: build
	$(LAB) tradeoff --scene scenes/tradeoff/cube_two_users.yaml --motion scenes/tradeoff/cube_press_slide.yaml \
	  --motion scenes/tradeoff/cube_press_hold.yaml --out out/tradeoff/cube

bench: build
	$(BUILD_DIR)/tests/cohaptic_bench $(BENCH_ARGS)

clean:
	rm -rf $(BUILD_DIR)
