PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test

.PHONY: demo test test-fast lint bench fuzz clean browser

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

# The report's browser test needs a headless Chromium: Debian's package, installed when missing
# and this machine can (root with apt-get); otherwise the browser tests skip and say why.
browser:
	@command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1 \
	  || command -v google-chrome >/dev/null 2>&1 \
	  || { if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	         echo "installing Debian's chromium for the browser tests"; \
	         apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null \
	           || echo "chromium could not be installed: the browser tests will skip"; \
	       else echo "no chromium and no root apt-get: the browser tests will skip"; fi; }

# The suite runs on two workers (pytest-xdist), each with one thread for OpenBLAS and OpenCV:
# their default pools would put four threads on two cores (about 10 % more CPU time measured
# on tests/heading, fusion, vo and gnss: 270 against 245 CPU-s). Bytecode is written even where
# PYTHONDONTWRITEBYTECODE is set: each worker, batch worker and command run by a test would
# otherwise compile the package and rewrite the tests' assertions anew (collection 14 s → 6 s).
TEST_ENV = OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 OPENCV_FOR_THREADS_NUM=1 PYTHONDONTWRITEBYTECODE=
test: $(TEST_STAMP) browser
	$(TEST_ENV) $(BIN)/python -m pytest -q -n 2

# The suite without the tests marked slow (generated drives, whole runs, real recordings):
# under 2 min on 2 cores, for the edit-test loop; `make test` still runs everything.
test-fast: $(TEST_STAMP) browser
	$(TEST_ENV) $(BIN)/python -m pytest -q -n 2 -m "not slow"

lint: $(TEST_STAMP)
	$(BIN)/ruff check . && $(BIN)/ruff format --check .

fuzz: $(TEST_STAMP)
	$(BIN)/python -m tests.fuzz.runner --cases 600 --workers 1 --json out/fuzz.json

bench: $(STAMP)
	$(BIN)/python benchmarks/vo_kitti.py

clean:
	rm -rf $(VENV) out
