# The two commands of crowdrecon (see README.md):
#   make demo   install what is missing, build, run the Madrid Arena case into out/
#   make test   install what is missing, build, run the whole suite with ctest
PRESET ?= release
BUILD  := build/$(PRESET)
JOBS   ?= $(shell nproc)
CROWDRECON := $(BUILD)/cli/crowdrecon

.PHONY: all deps build test test-long demo clean sanitize

all: build

deps:
	@bash scripts/install-deps.sh

build: deps
	@cmake --preset $(PRESET) >/dev/null
	@cmake --build --preset $(PRESET) -j $(JOBS)

test: build
	@ctest --preset $(PRESET) -j $(JOBS) --label-exclude long

# Long measurements (convergence in time step and vertex count), not in CI.
test-long: build
	@ctest --preset $(PRESET) --label-regex long --output-on-failure

demo: build
	@bash scripts/demo.sh $(CROWDRECON) out

sanitize:
	@$(MAKE) test PRESET=sanitize

clean:
	rm -rf build out
