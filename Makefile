# vista: the commands users and CI run. See README.md.
SHELL := /bin/bash
# lavapipe (Mesa's software Vulkan) prints a harmless warning without this.
export XDG_RUNTIME_DIR ?= /tmp
CARGO ?= cargo
VISTA := target/debug/vista

.PHONY: demo test golden curves seed-study bench fuzz mutants scaling device-figures coverage-cost lavapipe swiftshader validation browser lcov python build

lavapipe:
	bash ci/install-lavapipe.sh

swiftshader: lavapipe
	bash ci/install-swiftshader.sh

validation: lavapipe
	bash ci/install-validation.sh

browser:
	bash ci/install-browser.sh

# genhtml, which a test runs on the lcov.info of check --coverage.
lcov:
	bash ci/install-lcov.sh

# python3, for examples/sources' template renderer ([source] command).
python:
	bash ci/install-python.sh

build:
	$(CARGO) build -p vista-cli

# Render every preset into out/, check every golden case, print the report path.
demo: lavapipe build
	bash ci/demo.sh $(VISTA) out

# The whole suite (what .ci/run calls): `cargo test --workspace`, two test
# binaries at a time (ci/test-parallel.sh; JOBS=1 for one at a time): unit
# tests, CPU references, invariants, and every golden case on lavapipe
# under the validation layer; every golden case again on SwiftShader and in
# headless Chromium's WebGPU; then a closing count, and proof that without
# an adapter the GPU tests are reported skipped, never ok.
test: lavapipe swiftshader validation browser lcov python
	mkdir -p target
	# The workspace's test binaries, two at a time, its golden harness on
	# lavapipe under the Khronos validation layer (any message fails the
	# case), and two more runs of the golden harness: every golden case again
	# on SwiftShader (other-driver thresholds, expectations from
	# golden/cases.toml) and in headless Chromium's WebGPU (the
	# project's WGSL, or naga's rewrite of a naga_oil module, through Tint
	# and Dawn). Each writes its own report.
	set -o pipefail; CARGO=$(CARGO) GOLDEN_ENV=VISTA_VALIDATION=1 PASSES=$$'VISTA_BACKEND=swiftshader\nVISTA_BACKEND=browser' \
		bash ci/test-parallel.sh 2>&1 | tee target/test.log
	@echo "---- examples/harness-crate: another crate's cargo test running its golden cases through vista::harness::main()"
	set -o pipefail; CARGO=$(CARGO) bash ci/harness-example.sh 2>&1 | tee -a target/test.log
	bash ci/test-summary.sh target/test.log
	bash ci/no-gpu-skips.sh

# check against check --coverage on the built-ins and examples/, each with
# a fresh Mesa cache: the table in docs/performance.md.
coverage-cost: lavapipe build
	bash ci/coverage-cost.sh $(VISTA) 1

# Re-render goldens after an intended change (CASE=glob to select; refused under CI=true).
golden: lavapipe build
	$(VISTA) bless $(if $(CASE),--case '$(CASE)')

# Regenerate the step-count/quality curves in docs/curves.
curves: lavapipe build
	bash ci/curves.sh $(VISTA) docs/curves

# The seed's clouds quality study on the whole landscape frame, on two
# scenes: vista's seed frame (a flat slab) into docs/seed-study/slab, the
# source material's (a cloud shell, preset seed-scene) into
# docs/seed-study/shell, side by side in docs/seed-study/README.md (480x270
# on lavapipe; SIZE=1920x1080 on a hardware GPU with
# VISTA_STUDY_ARGS="--backend gpu" and VISTA_MAX_WORK raised). Not part of make test.
seed-study: lavapipe build
	bash ci/seed-study.sh $(VISTA) docs/seed-study/slab $(or $(SIZE),480x270) seed
	bash ci/seed-study.sh $(VISTA) docs/seed-study/shell $(or $(SIZE),480x270) seed-scene
	bash ci/seed-study-index.sh docs/seed-study

# The hardware-GPU figures into docs/device: `vista bench` for every
# kernel and the seed study on both scenes at 1920x1080 with --backend gpu
# (BACKEND=lavapipe SIZE=64x36 tries it without a GPU). Never part of make test.
device-figures: build
	bash ci/device-figures.sh $(VISTA) docs/device $(or $(SIZE),1920x1080)

# Mutation score of every kernel's suite into docs/mutants (not part of make test).
mutants: lavapipe build
	bash ci/mutants.sh $(VISTA) docs/mutants

# The fuzz test of make test (200 rounds from a fixed seed), 20,000 rounds
# from a new seed; an input that fails is kept in tests/fuzz/ and replayed
# by every later run. Its hostile-project classes (symlinks out of the
# project, FIFOs and devices in place of read files, shapes past the memory
# budget, includes and expressions past the parsers' depth, each through the
# binary) run every sub-case once in make test and 500 rounds each here;
# the gaps they once found run as fixed rounds too (ONCE_OPEN in
# crates/vista-cli/tests/fuzz.rs).
fuzz:
	VISTA_FUZZ_ITERATIONS=20000 VISTA_FUZZ_SEED=$$(date +%s) $(CARGO) test -p vista-cli --test fuzz -- --nocapture

bench: lavapipe
	$(CARGO) bench -p vista --features bench

# vista check's time, memory and report size per case against image size
# (64^2 .. 2048^2) and case count (COUNTS, default 100 1000), passing and
# failing: a markdown table for docs/performance.md (not part of make test).
scaling: lavapipe build
	bash ci/scaling.sh $(VISTA) $(or $(COUNTS),100 1000)
