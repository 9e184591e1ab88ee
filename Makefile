# kauri: the two commands a new user needs are `make demo` and `make test`.
PYTHON ?= python3
BUILD_DIR := $(shell $(PYTHON) scripts/build_dir.py)

.PHONY: build demo test test-cpp test-python bench bench-quick clean

build:
	./scripts/bootstrap

demo: build
	$(PYTHON) -m kauri render -o demo.exr

test: build
	ctest --test-dir $(BUILD_DIR) --output-on-failure -j2
	$(PYTHON) -m pytest -q tests/python

# bench: the full peer suite (kauri vs Mitsuba 3 and Cycles; report in bench/results/) plus the
# demo-scene, layered-material, colour-noise and light-tree micro-benchmarks. bench-quick: the suite at low res / spp.
bench: build
	$(PYTHON) bench/suite.py
	$(PYTHON) bench/bench_demo.py
	$(PYTHON) bench/bench_layers.py
	$(PYTHON) bench/colour_noise.py
	"$$($(PYTHON) scripts/build_dir.py)/kauri_bench_light_tree"

bench-quick: build
	$(PYTHON) bench/suite.py --quick

clean:
	rm -rf build demo.exr demo.png
