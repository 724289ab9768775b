# The two commands of crowdrecon (see README.md):
#   make demo   install what is missing, build, run the Madrid Arena case into out/
#   make test   install what is missing, build, run the whole suite with ctest
#   make validate  the validation suite on the validated crowd and the paper's
#               model side by side into out/validation (docs/validation.md)
#   make fuzz   build the libFuzzer harnesses (clang) and run each for
#               FUZZ_SECONDS (default 60) s; FUZZ_HARNESSES picks some (docs/fuzzing.md)
PRESET ?= release
BUILD  := build/$(PRESET)
JOBS   ?= $(shell nproc)
CROWDRECON := $(BUILD)/cli/crowdrecon
FUZZ_SECONDS ?= 60
FUZZ_HARNESSES ?=

.PHONY: all deps build test test-long demo clean sanitize fuzz validate

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

# The whole validation suite (docs/validation.md): every test on each profile,
# side by side; run again to continue or to reuse the runs done.
VALIDATION_PROFILES ?= venues/profiles/validated.json venues/validation/profiles/paper.json
validate: build
	@$(CROWDRECON) validate $(foreach p,$(VALIDATION_PROFILES),--profile $(p)) -o out/validation --jobs $(JOBS)

# The unit and command-line tests (all but `long`; there the whole-scenario
# tests count as long, tests/CMakeLists.txt) under AddressSanitizer and
# UndefinedBehaviorSanitizer: -O1, no benchmarks (CMakePresets.json). CI runs it
# after `make test`.
sanitize:
	@$(MAKE) test PRESET=sanitize

# The fuzz preset builds only the harnesses and the libraries they need.
fuzz: deps
	@bash scripts/install-fuzz-deps.sh
	@cmake --preset fuzz >/dev/null
	@cmake --build --preset fuzz -j $(JOBS)
	@bash scripts/fuzz.sh build/fuzz $(FUZZ_SECONDS) $(FUZZ_HARNESSES)

clean:
	rm -rf build out
