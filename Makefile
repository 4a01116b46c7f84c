# Two commands set everything up on a fresh machine:
#   make demo   installs AgentChord and runs the main job (offline, CPU, embedded defaults)
#   make test   installs AgentChord with its test tools and the learning stack, and runs the test suite
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
STAMP_TEST := $(VENV)/.installed-test
PYTEST_ARGS ?= -n 2 -m "not slow"
# lerobot 0.4.x (the last release for Python 3.11) pins torch<2.11, torchvision<0.26 and torchcodec<0.11;
# its dataset and policy code runs on the newer releases the `learn` extra installs, so it goes in
# without its own pins (pip install --no-deps). See docs/data.md.
LEROBOT ?= lerobot==0.4.4
# torchcodec (lerobot's video decoder) loads Debian's FFmpeg 5 libraries.
FFMPEG_LIBS := libavutil57 libavcodec59 libavformat59 libavdevice59 libavfilter8 libswscale6 libswresample4

.PHONY: install install-test system-deps system-deps-learn demo test test-all lint bench clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e ".[data]"
	touch $(STAMP)

# The test tools and the learning stack (torch, lerobot: several GB) only for the tests, so `make demo` stays light.
$(STAMP_TEST): $(STAMP) pyproject.toml
	$(BIN)/pip install -q -e ".[test,learn]"
	$(BIN)/pip install -q --no-deps "$(LEROBOT)"
	touch $(STAMP_TEST)

# Debian packages: graphviz draws graph figures (.svg/.png), libegl1 + libgl1-mesa-dri render videos headless.
system-deps:
	@missing=""; \
	command -v dot >/dev/null 2>&1 || missing="$$missing graphviz"; \
	ldconfig -p 2>/dev/null | grep -q libEGL.so.1 || missing="$$missing libegl1 libgl1-mesa-dri"; \
	$(call apt_install,$$missing,graph figures and headless video)

system-deps-learn:
	@missing=""; \
	ldconfig -p 2>/dev/null | grep -q libavdevice.so.59 || missing="$(FFMPEG_LIBS)"; \
	$(call apt_install,$$missing,lerobot's video decoding through torchcodec)

# $(call apt_install,PACKAGES,WHY): install the missing Debian packages with a clear message, or say what to do.
define apt_install
	if [ -n "$(1)" ]; then \
	  echo "AgentChord needs the Debian package(s): $(1) ($(2)). Installing with apt-get..."; \
	  SUDO=""; [ "$$(id -u)" -eq 0 ] || SUDO="sudo"; \
	  $$SUDO apt-get update -qq && $$SUDO apt-get install -y -qq $(1) >/dev/null \
	    || { echo "error: could not install $(1); install them yourself (apt-get install $(1))"; exit 1; }; \
	fi
endef

install: $(STAMP) system-deps

install-test: $(STAMP_TEST) system-deps system-deps-learn

demo: install
	$(BIN)/agentchord demo

test: install-test
	AGENTCHORD_REQUIRE_LEROBOT=1 $(BIN)/pytest $(PYTEST_ARGS)

# Lint: ruff's rules and mypy (both configured in pyproject.toml), and the import contracts.
lint: install-test
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/mypy
	$(BIN)/lint-imports

test-all: install-test
	AGENTCHORD_REQUIRE_LEROBOT=1 $(BIN)/pytest -n 2

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
