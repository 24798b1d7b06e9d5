# vista: the commands users and CI run. See README.md.
SHELL := /bin/bash
# lavapipe (Mesa's software Vulkan) prints a harmless warning without this.
export XDG_RUNTIME_DIR ?= /tmp
CARGO ?= cargo
VISTA := target/debug/vista

.PHONY: demo test golden curves bench lavapipe build

lavapipe:
	bash ci/install-lavapipe.sh

build:
	$(CARGO) build -p vista-cli

# Render every preset into out/, check every golden case, print the report path.
demo: lavapipe build
	bash ci/demo.sh $(VISTA) out

# The whole suite (what .ci/run calls): unit tests, CPU references,
# invariants, and every golden case on lavapipe; then a closing count, and
# proof that without an adapter the GPU tests are reported skipped, never ok.
test: lavapipe
	mkdir -p target
	set -o pipefail; $(CARGO) test --workspace 2>&1 | tee target/test.log
	bash ci/test-summary.sh target/test.log
	bash ci/no-gpu-skips.sh

# Re-render goldens after an intended change (CASE=glob to select; refused under CI=true).
golden: lavapipe build
	$(VISTA) bless $(if $(CASE),--case '$(CASE)')

# Regenerate the step-count/quality curves in docs/curves.
curves: lavapipe build
	bash ci/curves.sh $(VISTA) docs/curves

bench: lavapipe
	$(CARGO) bench -p vista
