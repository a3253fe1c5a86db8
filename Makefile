# drill_sim_ros - set-up, run and test. `make run` and `make test` create .venv on first use.
SHELL := /bin/bash
.SHELLFLAGS := -o pipefail -ec
VENV ?= .venv
PY := $(VENV)/bin/python
BIN := $(VENV)/bin
SYSTEM_PYTHON ?= python3

# Every ROS process we start stays on loopback, in its own DDS domain.
export ROS_AUTOMATIC_DISCOVERY_RANGE := LOCALHOST
ROS_DOMAIN_ID ?= $(shell $(SYSTEM_PYTHON) -c 'import random; print(random.randint(1, 101))')
export ROS_DOMAIN_ID
# Fast DDS writer tuning (config/fastdds_localhost.xml); a profile file of your own wins.
export FASTRTPS_DEFAULT_PROFILES_FILE := $(or $(FASTRTPS_DEFAULT_PROFILES_FILE),$(abspath config/fastdds_localhost.xml))
# The wheels need this for ament_index lookups (std_msgs share files, type hashes).
export AMENT_PREFIX_PATH := $(if $(AMENT_PREFIX_PATH),$(AMENT_PREFIX_PATH):$(abspath $(VENV)),$(abspath $(VENV)))
# The compiled kernel inlines functions of other model files, and numba's cache only notices
# changes to the kernel's own file: one cache per state of drill_sim_ros/model.
export NUMBA_CACHE_DIR ?= $(abspath .cache/numba)/$(shell cat drill_sim_ros/model/*.py drill_sim_ros/model/*/*.py | sha1sum | cut -c1-12)
export PYTHONUNBUFFERED := 1

RUN_DIR ?= runs/$(shell date -u +%Y%m%dT%H%M%SZ)
RUN_SECONDS ?= 0

.PHONY: venv run test lint bench clean colcon figures docs

venv: $(VENV)/.stamp

# Use a sourced ROS 2 Jazzy when there is one; otherwise rclpy comes from PyPI wheels.
MSGS := $(wildcard msgs/drill_sim_msgs/msg/*.msg) msgs/drill_sim_msgs/CMakeLists.txt \
  msgs/drill_sim_msgs/package.xml msgs/build_in_venv.sh
$(VENV)/.stamp: requirements.txt requirements-ros.txt requirements-msgs.txt setup.py $(MSGS)
	@if [ "$${ROS_DISTRO:-}" = "jazzy" ] && $(SYSTEM_PYTHON) -c 'import rclpy' 2>/dev/null; then \
	  echo "[venv] using the sourced ROS 2 Jazzy"; \
	  $(SYSTEM_PYTHON) -m venv --system-site-packages $(VENV); ros_req=""; \
	else \
	  echo "[venv] no ROS 2 Jazzy sourced: installing rclpy from PyPI wheels"; \
	  $(SYSTEM_PYTHON) -m venv $(VENV); ros_req="-r requirements-ros.txt -r requirements-msgs.txt"; \
	fi; \
	pipi() { $(PY) -m pip install --disable-pip-version-check "$$@" > $(VENV)/pip.log 2>&1 \
	  || { grep -v 'is ignored' $(VENV)/pip.log; echo "[venv] pip install failed"; exit 1; }; }; \
	echo "[venv] installing dependencies (first run: a few minutes, ~1 GB)"; \
	pipi $$ros_req -r requirements.txt; \
	pipi --no-build-isolation --no-deps -e .; \
	if [ -n "$$ros_req" ]; then \
	  echo "[venv] building the drill_sim_msgs interface package (about 30 s)"; \
	  msgs/build_in_venv.sh $(VENV) > $(VENV)/msgs-build.log 2>&1 \
	    || { tail -30 $(VENV)/msgs-build.log; echo "[venv] drill_sim_msgs failed to build"; exit 1; }; \
	fi; \
	$(PY) -c 'import rclpy, numba, mcap, rerun, drill_sim_ros' ; \
	$(PY) -m drill_sim_ros.viz.analytics_off; \
	touch $(VENV)/COLCON_IGNORE; \
	touch $@

# The node records runs/<utc>/run.mcap in-process; when it stops (Ctrl-C, SIGTERM or
# RUN_SECONDS), the recording is turned into runs/<utc>/run.rrd for the rerun viewer.
run: venv
	@mkdir -p $(RUN_DIR)
	@$(PY) -m drill_sim_ros.viz.analytics_off
	@trap : INT TERM; \
	$(BIN)/sim_node --ros-args --params-file config/sim.yaml \
	  -p record.path:=$(RUN_DIR)/run.mcap -p run_seconds:=$(RUN_SECONDS); \
	echo "[run] converting $(RUN_DIR)/run.mcap -> $(RUN_DIR)/run.rrd"; \
	$(BIN)/mcap_to_rerun $(RUN_DIR)/run.mcap -o $(RUN_DIR)/run.rrd && \
	echo "[run] replay: $(BIN)/mcap_replay $(RUN_DIR)/run.mcap   view: $(BIN)/rerun $(RUN_DIR)/run.rrd"

# The suite waits on wall time (ROS runs, live viewers) more than it computes: two
# pytest-xdist workers (each file on one, each worker its own DDS domain) run it in about
# 13 min instead of 21 (docs/testing.md). TEST_WORKERS=0 runs it serially.
TEST_WORKERS ?= 2
test: venv
	$(BIN)/ruff check drill_sim_ros tests benchmarks docs
	$(BIN)/pytest -n $(TEST_WORKERS) --dist loadfile

lint: venv
	$(BIN)/ruff check drill_sim_ros tests benchmarks docs

# The generated tables of the docs (parameters, topics) from the code's own tables;
# tests/test_docs.py fails when a committed page differs from what this writes.
docs: venv
	$(PY) docs/generate.py

# Benchmarks print figures (no pass/fail): kernel ns/step, node CPU and real-time factor,
# MCAP throughput, rerun bridge CPU, recording loss, maps, closed loop, lockstep, OPC UA, the
# gym per scenario; the kernel line includes its ns/step as a ratio to a naive reference step.
bench: venv
	$(PY) benchmarks/bench_kernel.py
	$(PY) benchmarks/bench_node.py
	$(PY) benchmarks/bench_mcap.py
	$(PY) benchmarks/bench_bridge.py
	$(PY) benchmarks/bench_recording_faults.py
	$(PY) benchmarks/bench_map.py
	$(PY) benchmarks/bench_closed_loop.py
	$(PY) benchmarks/bench_lockstep.py
	$(PY) benchmarks/bench_opcua.py
	$(PY) benchmarks/bench_gym.py
	$(PY) benchmarks/bench_fit.py
	$(BIN)/pytest -m study     # the slow comparisons against the independent solver

# The paper's figures and the field map (docs/gallery/*.png), computed on a local Dask
# cluster; FIGURES_CACHE keeps the maps as NetCDF so a re-run resumes them.
FIGURES_CACHE ?= runs/figures
figures: venv
	$(BIN)/drill_sim figures -o docs/gallery --cache $(FIGURES_CACHE)

# The ament_python install tree that `ros2 run drill_sim_ros sim_node` uses.
colcon: venv
	$(BIN)/colcon build --base-paths . --build-base build --install-base install \
	  $(if $(wildcard $(VENV)/share/drill_sim_msgs),--packages-skip drill_sim_msgs)
	@echo "source install/setup.sh, then: ros2 run drill_sim_ros sim_node (or install/drill_sim_ros/lib/drill_sim_ros/sim_node)"

clean:
	rm -rf build install log .pytest_cache .ruff_cache .cache
