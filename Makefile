# cohaptic: the two commands (see README.md).
#   make test   install missing packages, configure, build (Release), run every test
#   make demo   the same set-up, then the main job (SCENE=scenes/thin/noodle.yaml: the noodle's)
#   make tradeoff  the same set-up, then the speed/accuracy grid on the cube
#   make bench  the same set-up, then the benchmarks (BENCH_ARGS passes arguments through)
#   make bench-thin  the mass-spring benchmarks beside the thin-objects paper's Table 2
#   make bench-sphere  the sphere contact model's client tick and server step beside the dense solve
#   make bench-compliance  the brain's compliance by solves and by the Schur complement, same run
#   make brain-convergence  the brain's forces on its meshes against a finer reference mesh
#   make paired-rehearsal   the paper's experiments 1 and 2 as paired comparisons, simulated subjects
#   make attacks    eleven attacks from the network replayed on loopback, as a Markdown page
#   make results    every page of docs/results/ measured again and stamped (an hour or more)
#   make command-lines  docs/command-lines.md from the programs' --help
#   make format     every C++ file rewritten as clang-format writes it (.clang-format)
#   make fuzz       build the fuzz targets with clang (libFuzzer, ASan, UBSan) in build-asan
#                   and run each for FUZZ_SECONDS (default 15; 0 builds only), FUZZ_JOBS at once
#   make test-asan  the suite (ASAN_TESTS: all by default) built with clang, ASan + UBSan, in
#                   the same build-asan as the fuzz targets
#   make test-tsan  the threaded end-to-end tests (TSAN_TESTS) built with ThreadSanitizer in build-tsan
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
BENCH_ARGS ?=
# The demo's scene (empty: the brain).
SCENE ?=
# As typed, '$' included (make would expand it): the bench recipe reads it from the environment.
export COHAPTIC_BENCH_ARGS = $(value BENCH_ARGS)
# Extra CMake settings for the first configure, e.g. CMAKE_ARGS=-DCOHAPTIC_WARNINGS_AS_ERRORS=ON (CI).
CMAKE_ARGS ?=
# Unity builds (CMake compiles each target's sources eight to a unit): a build from scratch
# takes markedly less CPU, an edit recompiles its file's unit. UNITY=OFF for one file a unit.
UNITY ?= ON
UNITY_CMAKE = -DCMAKE_UNITY_BUILD=$(UNITY)
LAB := $(BUILD_DIR)/lab/cohaptic-lab

ASAN_BUILD_DIR ?= build-asan
TSAN_BUILD_DIR ?= build-tsan
FUZZ_SECONDS ?= 15
FUZZ_JOBS ?= 2
# CTest arguments choosing the ASan + UBSan tests: empty runs the whole suite; CI runs the
# unit label (every unit test and every fuzz corpus), the end-to-end tests being TSan's.
ASAN_TESTS ?=
# ASAN_SKIP_SLOW=1 leaves out the unit tests that take 20 s or more under ASan (each is a
# physics or geometry loop repeated thousands of times on a fine mesh; all run in the plain
# suite, and the lighter tests of the same suites run under ASan): CI's ASan stage, whose
# time they would double.
ASAN_SKIP_SLOW ?= 0
ASAN_SLOW_TESTS = SegmentCrossing\.TreeMatchesScan|Tradeoff\.ErrorIsMeasuredAgainstTheReference|NearestTriangleCandidates\.GiveTheFullScansAnswersOnTheBrain|Extremes\.FromNoHeldNodesToTheWholeSurface|MassSpringSimulation\.(NoodleSceneDroppedAndSlid|SubNetworkForceFollows|ClientForceThroughTheWire)|HertzConvergence|MassSpringScene\.ShippedNoodleScenesCompile|MassSpringFriction\.StaysBelow|SphereContact\.TwoSpheresAndHeldNodes|SeparationContact\.(SlidingStops|PushingTool|TwoCopies)|SeparationLaser\.|SeparationFracture\.|SceneModel\.EveryShipped|ContactModels\.ForcesFall|ObstacleClearance\.PointsItSkips|ObstacleDistance\.Colin27|LaparoscopyTradeoff\.|SeparationIr\.ClientForceEqualsTheServersThroughALaserGroove|SeparationScene\.TwoUsersTear|HertzGraded|SphereContact\.AtRandomPlacesOnTheBrain|SphereOutsideCandidates|VesselOnBrain\.SurgeonFeelsTheBrainThroughTheVein|MassSpringSimulation\.(ToolPushingTheTube|TubeDraggedByItsEnd)|PushInTime\.(FreeBelowOnBehindBelowFixed|ForceFollowsTheNonlinearStatic)|FemPairScene\.TheShippedScenesSurgeons|InteractionScene\.(BehindBoxCarries|ClientFeelsTheBehindBox)|SphereObstacle\.TheBrainOnItsSkull|IncrementalContactSolve\.AlongAMovingTool|SimulationCopy\.StepsBitForBitLikeTheOriginalAndApartFromIt/(brain|block_two_spheres)
# What test-asan builds: everything by default; CI names the unit tests' program (the fuzz
# targets are already built by `make fuzz`), not the end-to-end tests it leaves to TSan.
ASAN_TARGETS ?= all
# ThreadSanitizer runs the end-to-end sessions, whose server and client processes (built
# with TSan too) run every thread the system has: the haptic loop and its hand-overs, the
# transport's I/O threads, the server's simulation loop. These ones check behaviour, not
# timing (TSan slows a program 5 to 15 times): two users' forces against the offline
# evaluation, IRs over a lossy link, a server restart and reconnection, a recording
# verified bit for bit, and the security tests (participant keys, no plaintext, stale and
# old peers, the participant limit).
TSAN_TESTS ?= EndToEnd\.ClientForcesEqualOfflineEvaluationAndTheFullSolve|EndToEnd\.OnALossyLinkEveryIrArrivesOverTcp|EndToEnd\.AServerRestartFadesTheForceOutAndTheClientReconnects|Replay\.ATwoUserSessionVerifiesBitForBit|Security\.
# Sanitizer and fuzz builds: clang, -O1 with line tables only (file:line in every report,
# half the compile time of -O2 -g), and assertions on (Eigen's index checks too); no
# benchmarks. The ASan build is also the fuzzing build (COHAPTIC_FUZZ: coverage
# instrumentation in every library, libFuzzer's main in the fuzz targets only), so the
# libraries are compiled once for both.
SANITIZER_CMAKE = -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_CXX_FLAGS_DEBUG="-O1 -gline-tables-only" -DCOHAPTIC_BUILD_BENCHMARKS=OFF $(UNITY_CMAKE)
SANITIZER_ENV = ASAN_OPTIONS=detect_leaks=1:detect_stack_use_after_return=1 UBSAN_OPTIONS=print_stacktrace=1 \
  TSAN_OPTIONS=second_deadlock_stack=1:suppressions=$(CURDIR)/tests/tsan.supp

.PHONY: all deps configure build test format demo probe-demo tradeoff bench bench-thin bench-sphere bench-compliance brain-convergence paired-rehearsal attacks results command-lines fuzz test-asan test-tsan clean

all: build

deps:
	@./deploy/install-deps.sh

$(BUILD_DIR)/CMakeCache.txt: | deps
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) $(UNITY_CMAKE) $(CMAKE_ARGS)

configure: deps $(BUILD_DIR)/CMakeCache.txt

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	@status=0; ctest --test-dir $(BUILD_DIR) --output-on-failure -j $(JOBS) \
	  --resource-spec-file $(abspath $(BUILD_DIR))/ctest-resources.json || status=$$?; \
	  tests/report_skipped.sh $(BUILD_DIR); exit $$status

# The main job: the two-surgeon brain demo. A server and two haptic clients (hand models
# following the surgeons' scripted motions) on loopback, P1, about 20 s; prints a summary
# table, writes out/demo/report.json, and fails if the session was unhealthy. SCENE names
# another scene with surgeons' scripts beside it (scenes/thin/noodle.yaml: the noodle's demo).
demo: build
	@BUILD_DIR=$(BUILD_DIR) ./deploy/run-demo.sh $(SCENE)

# The probe on the paper's cube, through the intermediate representation: a tool pressed
# 1, 2, 5 and 10 mm into the front face's centre, then two tools together.
probe-demo: build
	@$(LAB) probe --scene scenes/cube.yaml --separately --tool 0,0,-1 --tool 0,0,-2 --tool 0,0,-5 --tool 0,0,-10
	@echo
	@$(LAB) probe --scene scenes/cube.yaml --tool 30,-20,-5 --tool -60,60,-3 --contact-model point \
	  --boundary-nodes 300 --ir-precision f32 --log-level warn

# Speed against accuracy on the paper's cube (docs/speed-versus-accuracy.md "Speed versus accuracy"): every
# setting against the full solve on an 18-division mesh; about a minute.
TRADEOFF_OUT ?= out/tradeoff/cube
tradeoff: build
	$(LAB) tradeoff --scene scenes/tradeoff/cube_two_users.yaml --motion scenes/tradeoff/cube_press_slide.yaml \
	  --motion scenes/tradeoff/cube_press_hold.yaml --out $(TRADEOFF_OUT)

# Eleven attacks from the network replayed against a server on loopback while real clients
# use it (docs/security.md "Attacks replayed"), as the Markdown page docs/results/attacks.md
# holds; about two minutes; exit 1 if one got through.
attacks:
	@$(MAKE) --no-print-directory build >&2
	@$(BUILD_DIR)/tests/cohaptic_attacks
	@tests/results_stamp.sh

# Every C++ source and header rewritten as clang-format writes it (.clang-format); the test
# Format.EverySourceFileIsAsClangFormatWritesIt fails on any line that differs.
format:
	@tests/format_sources.sh

# docs/command-lines.md from the built programs' --help (a test checks that it still is).
command-lines:
	@$(MAKE) --no-print-directory build >&2
	@tests/command_lines_page.sh $(BUILD_DIR) > docs/command-lines.md

# Every page of docs/results/ measured again, each by its own command above, and stamped
# with the commit, the date and the machine (an hour or more on two cores, most of it the
# brain's reference mesh). The paired-comparison studies run afresh.
results:
	@$(MAKE) --no-print-directory build
	$(MAKE) --no-print-directory attacks > docs/results/attacks.md
	$(MAKE) --no-print-directory bench-sphere > docs/results/sphere-contact-speed.md
	BUILD_DIR=$(BUILD_DIR) deploy/sphere-contact-bytes.sh > docs/results/sphere-contact-bytes.md
	$(MAKE) --no-print-directory bench-compliance > docs/results/compliance-speed.md
	$(MAKE) --no-print-directory bench-thin > docs/results/mass-spring-speed.md
	tests/results_page.sh docs/results/hertz-nu030/hertz.md $(LAB) hertz --out docs/results/hertz-nu030
	tests/results_page.sh docs/results/hertz-nu045/hertz.md \
	  $(LAB) hertz --element nodal_pressure_tet --poisson-ratio 0.45 --out docs/results/hertz-nu045
	tests/results_page.sh docs/results/tradeoff-cube/tradeoff.md \
	  $(MAKE) --no-print-directory tradeoff TRADEOFF_OUT=docs/results/tradeoff-cube
	tests/results_page.sh docs/results/tradeoff-brain/tradeoff.md \
	  $(LAB) tradeoff --scene scenes/tradeoff/brain.yaml --reference-scene scenes/tradeoff/brain_fine.yaml \
	  --motion scenes/tradeoff/brain_press_slide.yaml --motion scenes/tradeoff/brain_press_hold.yaml \
	  --sample-rate-hz 1000 --out docs/results/tradeoff-brain
	tests/results_page.sh docs/results/stability/stability.md $(LAB) stability --out docs/results/stability
	tests/results_page.sh docs/results/objects-push/objects_push_in_time.md \
	  $(LAB) objects-push --in-time --out docs/results/objects-push
	rm docs/results/objects-push/objects_push_in_time.csv  # every step of every curve: megabytes
	# After the in-time run, which writes the quasi-static page too (without its command line).
	tests/results_page.sh docs/results/objects-push/objects_push.md \
	  $(LAB) objects-push --out docs/results/objects-push
	rm -rf out/paired && $(MAKE) --no-print-directory paired-rehearsal > docs/results/paired-comparisons.md
	$(MAKE) --no-print-directory brain-convergence > docs/results/brain-convergence.md

# BENCH_ARGS reaches the program through the environment, split at spaces and otherwise as
# typed (no globbing, no pipes): BENCH_ARGS="--benchmark_filter=naive|incremental" works.
# The set-up's output goes to stderr, so that stdout is only the table, JSON or CSV asked for.
bench:
	@$(MAKE) --no-print-directory build >&2
	@set -f; exec $(BUILD_DIR)/tests/cohaptic_bench $$COHAPTIC_BENCH_ARGS

# The mass-spring body's benchmarks beside the thin-objects paper's Table 2, its largest
# stable steps and a client's tick against sections sent, as Markdown (about a minute).
bench-thin:
	@$(MAKE) --no-print-directory build >&2
	@tests/mass_spring_tables.sh $(BUILD_DIR)/tests/cohaptic_bench

# The sphere contact model's client tick (50 to 700 nodes in contact) and server step (400),
# each beside the dense solve in the same run, as Markdown (about a minute; the first
# run meshes the block and solves its compliance, another minute, cached on disk).
bench-sphere:
	@$(MAKE) --no-print-directory build >&2
	@tests/sphere_contact_tables.sh $(BUILD_DIR)/tests/cohaptic_bench

# The compliance of the brain's row nodes by solves and by the Schur complement, in the same
# run, on each brain mesh, as Markdown (a few minutes).
bench-compliance:
	@$(MAKE) --no-print-directory build >&2
	@tests/compliance_tables.sh $(BUILD_DIR)/tests/cohaptic_bench

# The brain's forces on its 9 mm and graded meshes against a mesh twice as fine near the
# tools, both tools pressing, the skull holding the brain, along their presses, as Markdown
# (the reference by the full sparse solve, minutes per point).
brain-convergence:
	@$(MAKE) --no-print-directory build >&2
	@tests/brain_convergence_table.sh $(BUILD_DIR)/lab/cohaptic-lab

# The paper's first two experiments as paired comparisons rated by simulated subjects:
# `make paired-rehearsal > docs/results/paired-comparisons.md`.
paired-rehearsal:
	@$(MAKE) --no-print-directory build >&2
	@tests/paired_rehearsal_page.sh $(BUILD_DIR)/lab/cohaptic-lab

$(ASAN_BUILD_DIR)/CMakeCache.txt: | deps
	cmake -S . -B $(ASAN_BUILD_DIR) $(SANITIZER_CMAKE) -DCOHAPTIC_FUZZ=ON

fuzz: $(ASAN_BUILD_DIR)/CMakeCache.txt
	cmake --build $(ASAN_BUILD_DIR) -j $(JOBS) --target fuzz_targets
	@if [ "$(FUZZ_SECONDS)" != 0 ]; then \
	  FUZZ_SECONDS=$(FUZZ_SECONDS) FUZZ_JOBS=$(FUZZ_JOBS) tests/fuzz/run_fuzzers.sh $(ASAN_BUILD_DIR); fi

test-asan: $(ASAN_BUILD_DIR)/CMakeCache.txt
	cmake --build $(ASAN_BUILD_DIR) -j $(JOBS) --target $(ASAN_TARGETS)
	$(SANITIZER_ENV) ctest --test-dir $(ASAN_BUILD_DIR) --output-on-failure -j $(JOBS) $(ASAN_TESTS) \
	  $(if $(filter 1,$(ASAN_SKIP_SLOW)),-E '$(ASAN_SLOW_TESTS)')

test-tsan: deps
	cmake -S . -B $(TSAN_BUILD_DIR) $(SANITIZER_CMAKE) -DCOHAPTIC_SANITIZE=thread
	cmake --build $(TSAN_BUILD_DIR) -j $(JOBS) --target cohaptic_e2e_tests
	$(SANITIZER_ENV) ctest --test-dir $(TSAN_BUILD_DIR) --output-on-failure -j $(JOBS) -R '$(TSAN_TESTS)'

clean:
	rm -rf $(BUILD_DIR) $(ASAN_BUILD_DIR) $(TSAN_BUILD_DIR)
