# Two commands set up a fresh clone: `make demo` (environment + main job on the sample) and `make test`.
PYTHON ?= python3.11
VENV ?= .venv
BIN := $(VENV)/bin
SAMPLE := data/sample

.PHONY: setup demo test docs bench browser clean speech-audio speech-bench

setup: $(VENV)/.installed

# torch first and pinned: any other torch spec pulls GBs of CUDA wheels.
$(VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q torch==2.13.0
	$(BIN)/pip install -q -e ".[dev,vectors,docs]"
	touch $@

# The main job: the whole pipeline (ingest, frames, train, ratings, evaluation, checkpoints) on the sample.
demo: setup
	PREFECT_SERVER_ANALYTICS_ENABLED=false $(BIN)/python -m flows.pipeline
	$(BIN)/lmcr srl "could you pour me some water?"

# The browser step may fail (no node, no npm registry): the headless preview test then skips.
# Two pytest workers (pytest-xdist): most tests are one busy process, and CI has two cores.
test: setup
	-$(MAKE) browser
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict -d build/site
	$(BIN)/ruff check lmcr flows tests bench docs
	$(BIN)/ruff format --check lmcr flows tests bench docs
	$(BIN)/python -m pytest -q -n 2 --dist worksteal --durations=10

# Headless Chromium from the npm registry (@sparticuz/chromium bundles the binary) for the HIT preview check.
browser: annotation/browser/node_modules/.installed

annotation/browser/node_modules/.installed: annotation/browser/package-lock.json
	cd annotation/browser && npm ci --no-audit --no-fund --loglevel=error
	touch $@

# The documentation site (mkdocs.yml, docs/): the CLI reference, schema and results pages are generated.
docs: setup
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict -d build/site
	@echo "open build/site/index.html"

bench: setup
	$(BIN)/python bench/bench_ingest.py
	$(BIN)/python bench/bench_srl.py

clean:
	rm -rf $(VENV) data/staging data/lmcr.duckdb data/lmcr.duckdb.wal annotation/browser/node_modules

# Spoken dev instructions (espeak-ng voices x rates, clean / 20 dB noise / telephone) and the recogniser
# bench on them: `make speech-audio SHARED=/path/to/shared` (or $$LMCR_SHARED_DIR); LMCR_DATA_DIR names a
# store with frames (the parser's resources); add ASR="--asr sphinx" for pocketsphinx (after `lmcr speech-lm`).
SHARED ?= $(LMCR_SHARED_DIR)
SPEECH_AUDIO ?= data/speech-dev
speech-audio: setup
	@test -n "$(SHARED)" || { echo "speech-audio: set SHARED=/path/to/shared (or LMCR_SHARED_DIR)"; exit 1; }
	$(BIN)/python bench/render_speech.py --instructions $(SHARED)/eval/instructions_dev.jsonl --out $(SPEECH_AUDIO)

speech-bench: setup
	$(BIN)/python bench/bench_speech.py --index $(SPEECH_AUDIO)/index.jsonl $(ASR)
