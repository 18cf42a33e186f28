PYTHON ?= python3.11
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test
# two test workers per core, at least four: many tests wait on a served app, a database or a
# browser, so a core is idle while its one worker waits (5 min 17 s against 7 min 9 s on 2 cores)
TEST_WORKERS ?= $(shell n=$$(nproc 2>/dev/null || echo 2); [ $$((n * 2)) -lt 4 ] && echo 4 || echo $$((n * 2)))

.PHONY: run test lint bench clean haproxy chromium

$(BIN)/python:
	@command -v $(PYTHON) >/dev/null 2>&1 || { echo "Python 3.11 is needed: install it or run 'make PYTHON=/path/to/python3.11 ...'"; exit 1; }
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP): $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install --quiet -e .
	@touch $@

$(TEST_STAMP): $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install --quiet -e '.[test]'
	@touch $@ $(STAMP)

run: $(STAMP)
	$(BIN)/workbench

test: $(TEST_STAMP) haproxy chromium
	$(BIN)/ruff check .
	$(BIN)/lint-imports
	$(BIN)/mypy
	$(BIN)/python -m pytest -n $(TEST_WORKERS)

# the balancer test needs HAProxy: installed here as root where apt-get is, else skipped
# (never a reason for the build to fail)
haproxy:
	@export PATH="$$PATH:/usr/local/sbin:/usr/sbin:/sbin"; \
	command -v haproxy >/dev/null 2>&1 || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    echo "installing Debian's haproxy for the balancer test"; \
	    export DEBIAN_FRONTEND=noninteractive; \
	    apt-get install -y -q haproxy >/dev/null 2>&1 || \
	      { apt-get update -q >/dev/null 2>&1 && apt-get install -y -q haproxy >/dev/null 2>&1; } || \
	      echo "haproxy could not be installed: the balancer test will be skipped"; \
	  else \
	    echo "no haproxy: the balancer test will be skipped (install the haproxy package)"; \
	  fi; \
	}

# the browser test drives Debian's Chromium with Playwright: installed here as root where
# apt-get is, else that test is skipped (never a reason for the build to fail)
chromium:
	@command -v chromium >/dev/null 2>&1 || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    echo "installing Debian's chromium for the browser test"; \
	    export DEBIAN_FRONTEND=noninteractive; \
	    apt-get install -y -q chromium >/dev/null 2>&1 || \
	      { apt-get update -q >/dev/null 2>&1 && apt-get install -y -q chromium >/dev/null 2>&1; } || \
	      echo "chromium could not be installed: the browser test will be skipped"; \
	  else \
	    echo "no chromium: the browser test will be skipped (install the chromium package)"; \
	  fi; \
	}

lint: $(TEST_STAMP)
	$(BIN)/ruff check .
	$(BIN)/lint-imports
	$(BIN)/mypy

bench: $(STAMP)
	@for b in bench/*.py; do echo "== $$b"; $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .ruff_cache .hypothesis
