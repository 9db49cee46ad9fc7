# occull — the two commands:
#   make demo   install dependencies, build (Release), run the main benchmark
#   make test   install dependencies, build, run every test (ctest)
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: demo test deps data configure build install clean

demo: build
	./$(BUILD)/occull bench

test: build data
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

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

clean:
	rm -rf $(BUILD)
