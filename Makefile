# Two commands do all set-up on a fresh machine: `make demo` and `make test`.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
export MUJOCO_GL ?= egl

.PHONY: demo test lint bench clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q torch==2.13.0
	$(BIN)/python -m pip install -q -e ".[dev]"
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/teachfit quickstart --out out/quickstart

# `make test` lints first (ruff check, ruff format --check and mypy) while numba builds the real
# Franka's tick into its cache on the other core (else the first test to connect compiles it,
# ~15 s), then runs the tests
test: $(STAMP)
	$(BIN)/python -c "from teachfit.robot.franka import kernel; kernel.compile_entries()" & \
	warm=$$!; $(MAKE) --no-print-directory lint; lint=$$?; wait $$warm; \
	[ $$lint -eq 0 ] && $(BIN)/python -m pytest -n 2 --durations=10

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/ruff format --check src tests benchmarks
	$(BIN)/mypy

bench: $(STAMP)
	$(BIN)/teachfit bench sim

clean:
	rm -rf $(VENV) out .pytest_cache .ruff_cache .mypy_cache
