# stereo-servo: `make demo` runs the main job on embedded defaults, `make test` runs the tests.
# Both create the virtual environment and install what they need on a fresh machine.

SHELL := /bin/bash
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
OUT ?= out
DATA ?= $(abspath ../shared/data)
# tests and benchmarks find the Middlebury scenes through this variable
export STEREO_SERVO_DATA ?= $(if $(wildcard $(DATA)/middlebury/index.json),$(DATA),)

.PHONY: demo test test-setup test-firmware lint typecheck bench venv system-deps browser-deps platformio protocol firmware flash mutants fuzz clean

# the install in two steps: the package with its own dependencies first, which is what the warm
# step needs, then the test and Ray extras (most of the download: Ray, playwright, mypy, ruff),
# which make -j2 fetches while the warm step compiles
$(BIN)/.core: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --disable-pip-version-check -e .
	touch $@

$(BIN)/.installed: $(BIN)/.core
	$(BIN)/pip install --quiet --disable-pip-version-check -e '.[test,ray]'
	touch $@

# numba compiles now (2 processes), not in the user's first run
$(BIN)/.warmed: $(BIN)/.core
	$(BIN)/python -m host.warm
	touch $@

venv: $(BIN)/.installed $(BIN)/.warmed

system-deps:
	@bash tools/system-deps.sh

# Debian's chromium for the live view's browser test (tests/view)
browser-deps: system-deps
	@bash tools/browser-deps.sh

# PlatformIO Core in .venv and its atmelavr platform from Debian and PyPI, under build/platformio
# (tools/platformio-offline.sh); exit 3 = no ../shared/platformio here, and the tests skip
PIO_CORE := $(abspath build/platformio)
platformio: $(BIN)/.installed system-deps
	@bash tools/platformio-offline.sh || [ $$? -eq 3 ]

demo: venv
	@mkdir -p $(OUT)
	$(BIN)/host eval --picture $(OUT)
	$(BIN)/host eval --matcher ncc --block-size 5 --border clip --lr-check 1 --fill --median 5
	$(BIN)/host tune --method paper --border clip --out $(OUT)/tuned.toml --plot $(OUT)/tuning.png
	$(BIN)/host servo --sim --border clip --num-disparities 48 --log $(OUT)/servo.csv --plot $(OUT)/servo.png
	@echo "pictures: $(OUT)/motorcycle.png (disparity), $(OUT)/tuning.png (tuning), $(OUT)/servo.png (servo run)"

# pytest-xdist: TEST_WORKERS processes, each test file whole on one of them (tests/conftest.py
# says what files share and how that is kept safe); TEST_WORKERS=0 runs in this process
TEST_WORKERS ?= 2
# the set-up in two jobs: the warm step's compiling (CPU) beside the installs (network, disk)
# and the checks; make test-setup alone runs them one after the other
test:
	$(MAKE) -j2 test-setup
	$(BIN)/python -m pytest -n $(TEST_WORKERS) --dist loadfile --no-loadscope-reorder --durations=40

test-setup: venv system-deps browser-deps platformio lint typecheck test-firmware

# the firmware ELFs the simavr tests load (the normal build and the one that hangs on demand),
# built here beside the warm step; pytest's own build (tests/conftest.py) then finds them up to
# date. A missing AVR toolchain is not an error here: the tests skip, saying so
test-firmware: system-deps
	-@$(MAKE) -s -C firmware/atmega328 >/dev/null
	-@$(MAKE) -s -C firmware/atmega328 TEST_HANG=1 >/dev/null

lint: $(BIN)/.installed
	$(BIN)/ruff check host tools bench tests

# mypy, strict on host/ as pyproject.toml's [tool.mypy] configures it (relaxations said there)
typecheck: $(BIN)/.installed
	$(BIN)/mypy

bench: venv
	$(BIN)/python bench/matcher.py
	$(BIN)/python bench/tuning.py
	$(BIN)/python bench/protocol.py
	$(BIN)/python bench/crc.py
	$(BIN)/python bench/firmware.py
	$(BIN)/python bench/link.py
	$(BIN)/python bench/servo.py
	$(BIN)/python bench/view.py
	$(BIN)/python bench/trials.py
	$(MAKE) fuzz
	$(BIN)/python bench/record.py
	$(MAKE) mutants

# firmware mutation testing (firmware/atmega328/mutants.toml): an unmutated control must pass,
# then every mutant must be killed by a behaviour test or be argued equivalent (tools/mutate.py);
# it takes tens of minutes, so it runs with the benchmarks, not in make test
mutants: venv system-deps
	@mkdir -p $(OUT)
	$(BIN)/python tools/mutate.py --table $(OUT)/mutants.md

# libFuzzer (clang, ASan + UBSan) on the frame parser and the firmware core, FUZZ_S seconds each
# from the committed corpus (make test runs a few seconds of it: tests/firmware/test_libfuzzer.py)
FUZZ_S ?= 300
fuzz: venv system-deps
	$(BIN)/python tools/fuzz.py --seconds $(FUZZ_S) --out build/fuzz

# regenerate everything derived from protocol/spec.toml (tests fail while it is stale)
protocol: venv
	$(BIN)/python tools/protogen.py

# the robot's firmware (firmware/atmega328/Makefile); flash with PORT=/dev/ttyACM0.
# PLATFORMIO=1 builds and uploads with PlatformIO instead (platformio.ini, env uno).
ifeq ($(PLATFORMIO),1)
firmware: platformio
	PLATFORMIO_CORE_DIR=$(PIO_CORE) $(BIN)/pio run -e uno

flash: platformio
	PLATFORMIO_CORE_DIR=$(PIO_CORE) $(BIN)/pio run -e uno -t upload $(if $(PORT),--upload-port $(PORT))
else
firmware: system-deps
	$(MAKE) -C firmware/atmega328

flash: system-deps
	$(MAKE) -C firmware/atmega328 flash
endif

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache .pio build
