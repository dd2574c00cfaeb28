# Two commands set up a fresh clone: `make demo` (environment + main job on the sample) and `make test`.
PYTHON ?= python3.11
VENV ?= .venv
BIN := $(VENV)/bin
SAMPLE := data/sample

.PHONY: setup demo test bench clean

setup: $(VENV)/.installed

# torch first and pinned: any other torch spec pulls GBs of CUDA wheels.
$(VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q torch==2.13.0
	$(BIN)/pip install -q -e ".[dev]"
	touch $@

# The main job: the whole pipeline (ingest, frames, train, ratings, evaluation, checkpoints) on the sample.
demo: setup
	PREFECT_SERVER_ANALYTICS_ENABLED=false $(BIN)/python -m flows.pipeline
	$(BIN)/lmcr srl "could you pour me some water?"

test: setup
	$(BIN)/python -m pytest -q

bench: setup
	$(BIN)/python bench/bench_ingest.py
	$(BIN)/python bench/bench_srl.py

clean:
	rm -rf $(VENV) data/staging data/lmcr.duckdb
