PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test

.PHONY: demo test lint bench clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip

$(STAMP): $(BIN)/python pyproject.toml
	$(BIN)/pip install --quiet -e .
	touch $(STAMP)

$(TEST_STAMP): $(BIN)/python pyproject.toml
	$(BIN)/pip install --quiet -e ".[test]"
	touch $(STAMP) $(TEST_STAMP)

DEMO_SEQ := out/demo/sequence

demo: $(STAMP)
	$(BIN)/python -m vo_doppler.sim.vo_sequence $(DEMO_SEQ) --duration 20 --fps 10 --seed 1
	$(BIN)/vo-doppler vo $(DEMO_SEQ)/image_0 --calib $(DEMO_SEQ)/calib.yaml \
		--speed $(DEMO_SEQ)/speed.csv --gt $(DEMO_SEQ)/ground_truth_camera.kitti -o out/demo

test: $(TEST_STAMP)
	$(BIN)/python -m pytest -q

lint: $(TEST_STAMP)
	$(BIN)/ruff check . && $(BIN)/ruff format --check .

bench: $(STAMP)
	$(BIN)/python benchmarks/vo_kitti.py

clean:
	rm -rf $(VENV) out
