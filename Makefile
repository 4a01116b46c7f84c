# Two commands set everything up on a fresh machine:
#   make demo   installs AgentChord and runs the main job (offline, CPU, embedded defaults)
#   make test   installs AgentChord with its test tools and runs the test suite
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
PYTEST_ARGS ?= -n 2 -m "not slow"

.PHONY: install system-deps demo test test-all bench clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e ".[test]"
	touch $(STAMP)

# Debian packages: graphviz draws graph figures (.svg/.png), libegl1 + libgl1-mesa-dri render videos headless.
system-deps:
	@missing=""; \
	command -v dot >/dev/null 2>&1 || missing="$$missing graphviz"; \
	ldconfig -p 2>/dev/null | grep -q libEGL.so.1 || missing="$$missing libegl1 libgl1-mesa-dri"; \
	if [ -n "$$missing" ]; then \
	  echo "AgentChord needs the Debian package(s):$$missing (graph figures, headless video). Installing with apt-get..."; \
	  SUDO=""; [ "$$(id -u)" -eq 0 ] || SUDO="sudo"; \
	  $$SUDO apt-get update -qq && $$SUDO apt-get install -y -qq $$missing >/dev/null \
	    || { echo "error: could not install$$missing; install them yourself (apt-get install$$missing)"; exit 1; }; \
	fi

install: $(STAMP) system-deps

demo: install
	$(BIN)/agentchord demo

test: install
	$(BIN)/pytest $(PYTEST_ARGS)

test-all: install
	$(BIN)/pytest -n 2

bench: install
	$(BIN)/python benchmarks/bench_disturbances.py
	$(BIN)/python benchmarks/bench_episode.py
	$(BIN)/python benchmarks/bench_monitors.py
	$(BIN)/python benchmarks/bench_recovery_cost.py
	$(BIN)/python benchmarks/bench_perception.py
	$(BIN)/python benchmarks/bench_planning.py
	$(BIN)/python benchmarks/bench_solvers.py
	$(BIN)/python benchmarks/bench_remote_world.py

clean:
	rm -rf $(VENV) .pytest_cache .hypothesis
