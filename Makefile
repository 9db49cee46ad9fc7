# occull — the two commands:
#   make demo   install dependencies, build (Release), run the main benchmark
#   make test   install dependencies, build, run every test (ctest)
#   make test-asan   the same tests built with AddressSanitizer, LeakSanitizer and UBSan
#   make fuzz   fuzz every file reader for FUZZ_SECONDS each (libFuzzer, clang; build-fuzz/)
#   make fuzz-regress   every reader over its corpus in tests/corpus/, then briefly fuzzed, then a short
#                       randomized campaign against the conservative cullers (CI)
#   scripts/conservative-campaign.sh N   N random adversarial runs, every conservative culler verified
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: demo test test-asan fuzz fuzz-regress fuzz-build deps data configure build install clean gpu-pack

# The demo builds the tool alone (not the tests a newcomer did not ask for).
demo: configure
	cmake --build $(BUILD) -j $(JOBS) --target occull_cli
	./$(BUILD)/occull bench

test: build data
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# Every test again with AddressSanitizer, LeakSanitizer and UBSan (build-asan/).
test-asan: deps data
	cmake -S . -B $(BUILD)-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DOCCULL_SANITIZE=ON $(CMAKE_FLAGS)
	cmake --build $(BUILD)-asan -j $(JOBS)
	cd $(BUILD)-asan && ctest --output-on-failure -j $(JOBS)

# The readers of files made by others under libFuzzer, with ASan and UBSan.
FUZZ_SECONDS ?= 60
fuzz-build:
	./scripts/install-deps.sh --fuzz
	cmake -S . -B $(BUILD)-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
	  -DOCCULL_FUZZ=ON -DOCCULL_BUILD_TESTS=OFF -DOCCULL_BUILD_APPS=OFF $(CMAKE_FLAGS)
	cmake --build $(BUILD)-fuzz -j $(JOBS) --target fuzz_bsp fuzz_pk3 fuzz_path fuzz_profile fuzz_scene_spec fuzz_model

fuzz: fuzz-build
	./scripts/fuzz.sh $(BUILD)-fuzz run $(FUZZ_SECONDS)

fuzz-regress: fuzz-build build
	./scripts/fuzz.sh $(BUILD)-fuzz regress
	./scripts/conservative-campaign.sh 20 --short --seed 45 --occull $(BUILD)/occull

deps:
	./scripts/install-deps.sh

# The OpenArena maps (Quake 3 levels) the real-map tests and benchmarks use, into data/.
data: deps
	./scripts/fetch-data.sh

configure: deps
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

# make install PREFIX=/some/where
PREFIX ?= /usr/local
install: build
	cmake --install $(BUILD) --prefix $(PREFIX)

# A folder (.gpu/) to run occull on a GPU machine without a package registry (docs/cli.md, "On a GPU").
gpu-pack: deps
	./scripts/gpu-pack.sh .gpu

clean:
	rm -rf $(BUILD) $(BUILD)-asan $(BUILD)-fuzz
