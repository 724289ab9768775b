# The two commands of crowdrecon (see README.md):
#   make demo   install what is missing, build, run the Madrid Arena case into out/
#   make test   install what is missing, build, run the whole suite with ctest
PRESET ?= release
BUILD  := build/$(PRESET)
JOBS   ?= $(shell nproc)
CROWDRECON := $(BUILD)/cli/crowdrecon

.PHONY: all deps build test demo clean sanitize

all: build

deps:
	@bash scripts/install-deps.sh

build: deps
	@cmake --preset $(PRESET) >/dev/null
	@cmake --build --preset $(PRESET) -j $(JOBS)

test: build
	@ctest --preset $(PRESET) -j $(JOBS)

demo: build
	@bash scripts/demo.sh $(CROWDRECON) out

sanitize:
	@$(MAKE) test PRESET=sanitize

clean:
	rm -rf build out
