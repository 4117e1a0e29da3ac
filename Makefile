# sagcal developer commands. `make test` is the test command CI runs.
SHELL := /bin/bash
VENV := codegen/.venv
PYTHON := $(VENV)/bin/python
PYTHON3 ?= python3

.PHONY: all codegen codegen-check test lint bench bench-peers demo verify clean-venv

all: test

# A virtualenv with the pinned SymForce (codegen/requirements.txt); ignored by git.
$(VENV)/.installed: codegen/requirements.txt
	$(PYTHON3) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --disable-pip-version-check -r codegen/requirements.txt
	touch $@

## Regenerate generated/ from the symbolic model in codegen/.
codegen: $(VENV)/.installed
	$(PYTHON) codegen/generate.py --out generated

## Regenerate into a temporary folder and fail on any byte of difference from generated/.
codegen-check: $(VENV)/.installed
	$(PYTHON) codegen/generate.py --check generated

## The README's test command: generated code up to date, then every test of the crate.
test: codegen-check
	cargo test --all-targets
	cargo test --doc

lint:
	cargo fmt --all -- --check
	cargo clippy --all-targets -- -D warnings

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
