# sagcal developer commands. `make test` is the test command CI runs.
SHELL := /bin/bash
VENV := codegen/.venv
PYTHON := $(VENV)/bin/python
PYTHON3 ?= python3

.PHONY: all codegen codegen-check test lint bench bench-peers demo verify clean-venv python-venv python-test

# The Python package (python/): a virtualenv with maturin, numpy and pytest and
# the package built from this tree; ignored by git.
PY_VENV := python/.venv
PY_SOURCES := $(shell find python/src python/sagcal src generated -type f -not -name '*.pyc' -not -name '*.so' 2>/dev/null) \
	python/Cargo.toml python/Cargo.lock python/pyproject.toml python/README.md Cargo.toml $(wildcard robots/*.toml)

all: test

# A virtualenv with the pinned SymForce (codegen/requirements.txt); ignored by git.
$(VENV)/.installed: codegen/requirements.txt
	$(PYTHON3) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --disable-pip-version-check -r codegen/requirements.txt
	touch $@

# `pip install ./python` with the dev profile of python/Cargo.toml (opt-level 1,
# faer and nalgebra at 3: the root crate's test profile) into target/, where
# `cargo test` left the crates both builds share; rebuilt when a source changes.
$(PY_VENV)/.installed: python/requirements-dev.txt $(PY_SOURCES)
	$(PYTHON3) -m venv $(PY_VENV)
	$(PY_VENV)/bin/pip install --quiet --disable-pip-version-check -r python/requirements-dev.txt
	PATH="$(CURDIR)/$(PY_VENV)/bin:$$PATH" CARGO_TARGET_DIR=$(CURDIR)/target MATURIN_PEP517_ARGS="--profile dev --strip" \
		$(PY_VENV)/bin/pip install --quiet --disable-pip-version-check --no-build-isolation --no-deps --force-reinstall ./python
	touch $@

## The virtualenv python/.venv with the Python package `sagcal` built from this tree.
python-venv: $(PY_VENV)/.installed

## The Python package's tests, against the `sagcal` binary `cargo test` built.
python-test: $(PY_VENV)/.installed
	SAGCAL_BIN=$(CURDIR)/target/debug/sagcal $(PY_VENV)/bin/python -m pytest python/tests -q

## Regenerate generated/ from the symbolic model in codegen/.
codegen: $(VENV)/.installed
	$(PYTHON) codegen/generate.py --out generated

## Regenerate into a temporary folder and fail on any byte of difference from generated/.
codegen-check: $(VENV)/.installed
	$(PYTHON) codegen/generate.py --check generated

## The README's test command: generated code up to date, the lint, every test of
## the crate, the solver's and the calibration's tests once more on the portable
## path (the first run takes the AVX2 kernels where the CPU has them;
## `SAGCAL_SIMD=avx2 make test` fails on a CPU without AVX2: src/simd.rs), then
## the Python package's tests.
test: codegen-check lint
	cargo test --all-targets
	cargo test --doc
	SAGCAL_SIMD=portable cargo test --lib -- simd:: graph:: solver:: calib::
	SAGCAL_SIMD=portable cargo test --test solver --test final_cost --test calibration --test prepared_calibration \
		--test extended_model --test gross_errors --test cli_calibrate
	$(MAKE) python-test

## What a reviewer runs: formatting, clippy with warnings denied (the crate and the
## Python package), the API documentation with warnings denied.
lint:
	cargo fmt --all -- --check
	cargo fmt --manifest-path python/Cargo.toml --all -- --check
	cargo clippy --all-targets -- -D warnings
	CARGO_TARGET_DIR=$(CURDIR)/target cargo clippy --manifest-path python/Cargo.toml --all-targets -- -D warnings
	RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --quiet

## Criterion benches: generated Jacobians (analytic vs numerical) and solver scaling.
bench:
	cargo bench

## sagcal against apex-solver and factrs on the same problem (peers/, its own lock file;
## not part of `make test`): solvers interleaved in every round, min / median / max.
## Writes target/bench-peers/peers.json and peers.svg. `make bench-peers ARGS=--quick`: under a minute.
bench-peers:
	cargo run --release --manifest-path peers/Cargo.toml -- --out target/bench-peers $(ARGS)

demo:
	cargo run --release

verify:
	cargo run --release -- verify --robot robots/large.toml --data ../shared/data/recurdyn-large/recurdyn_large.csv

clean-venv:
	rm -rf $(VENV)
