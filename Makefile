# make render | test | bench | bench-peers | clean. System libraries come from tools/ensure_system_deps.sh,
# Python packages go into .venv (reinstalled when pyproject.toml, setup.py or this file changes).
PYTHON ?= python3
VENV := .venv
SCENE := scenes/cornell_box.json
PYTEST_ARGS ?=
LP_NUM_THREADS ?= $(shell nproc)
PIP_INSTALL := $(VENV)/bin/python -m pip install -q --disable-pip-version-check

.PHONY: render test bench bench-peers clean system-deps test-system-deps

render: system-deps $(VENV)/.installed
	@mkdir -p out
	$(VENV)/bin/vct render $(SCENE) --out out/cornell_box.png

test: test-system-deps $(VENV)/.installed-test
	$(VENV)/bin/python -m pytest -q $(PYTEST_ARGS)

bench: system-deps $(VENV)/.installed
	LP_NUM_THREADS=$(LP_NUM_THREADS) $(VENV)/bin/vct bench $(SCENE)

# This renderer and Godot 3's GIProbe (../shared/peers/godot-giprobe) in the same run, with the ratio.
bench-peers: system-deps $(VENV)/.installed
	LP_NUM_THREADS=$(LP_NUM_THREADS) $(VENV)/bin/python tools/bench_peers.py

clean:
	rm -rf out $(VENV)

system-deps:
	@bash tools/ensure_system_deps.sh

test-system-deps:
	@bash tools/ensure_system_deps.sh --test

$(VENV)/bin/python:
	$(PYTHON) -m venv $(VENV)

# Stamps: the venv is created once (order-only), packages are reinstalled when pyproject.toml,
# setup.py or this file changes.
$(VENV)/.installed: pyproject.toml setup.py Makefile | $(VENV)/bin/python
	$(PIP_INSTALL) -e .
	@touch $@

$(VENV)/.installed-test: pyproject.toml setup.py Makefile | $(VENV)/bin/python
	$(PIP_INSTALL) -e '.[test,reference,batch]'
	@touch $@ $(VENV)/.installed
