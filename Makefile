PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test

.PHONY: demo test lint bench fuzz clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip

$(STAMP): $(BIN)/python pyproject.toml
	$(BIN)/pip install --quiet -e .
	touch $(STAMP)

$(TEST_STAMP): $(BIN)/python pyproject.toml
	$(BIN)/pip install --quiet -e ".[test]"
	touch $(STAMP) $(TEST_STAMP)

demo: $(STAMP)
	$(BIN)/vo-doppler run sample_sequences/urban_canyon_small -o out/demo

test: $(TEST_STAMP)
	$(BIN)/python -m pytest -q

lint: $(TEST_STAMP)
	$(BIN)/ruff check . && $(BIN)/ruff format --check .

fuzz: $(TEST_STAMP)
	$(BIN)/python -m tests.fuzz.runner --cases 600 --workers 1 --json out/fuzz.json

bench: $(STAMP)
	$(BIN)/python benchmarks/vo_kitti.py

clean:
	rm -rf $(VENV) out
