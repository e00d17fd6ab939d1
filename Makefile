# One target per CI step. `make test` is what CI runs (see README.md and .ci/run).
PYTHON ?= .venv/bin/python

.PHONY: test lint fmt-check test-rust test-py stubtest bench fmt

test: lint test-rust test-py

lint: fmt-check
	cargo clippy --locked --workspace --all-targets -- -D warnings
	$(PYTHON) -m ruff check python tests
	$(PYTHON) -m mypy python/upperpose
	$(PYTHON) -m mypy.stubtest upperpose._upperpose

fmt-check:
	cargo fmt --all -- --check
	$(PYTHON) -m ruff format --check python tests

# Core and benches; the binding crate needs libpython to link and is tested through pytest.
test-rust:
	cargo test --locked
	cargo bench --locked --no-run

test-py:
	$(PYTHON) -m pytest

bench:
	cargo bench --locked

fmt:
	cargo fmt --all
	$(PYTHON) -m ruff format python tests
