#!/usr/bin/env bash
# Build the drill_sim_msgs interface package with the PyPI wheels' rosidl and install it into
# the venv given as $1 (its Python then imports drill_sim_msgs with no extra environment).
# Needs requirements-msgs.txt installed in that venv, cmake and a C/C++ compiler.
set -euo pipefail
venv=$(cd "$1" && pwd)
src=$(cd "$(dirname "$0")/drill_sim_msgs" && pwd)
py="$venv/bin/python"
build="$venv/build/drill_sim_msgs"
# The wheels' CMake exports name the Python and numpy headers of the machine that built them
# (/opt/python/cpXY-cpXY/...): point them at this venv's.
py_include=$("$py" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
np_include=$("$py" -c 'import numpy; print(numpy.get_include())')
{ grep -l '/opt/python/' "$venv"/share/*/cmake/*Export.cmake 2>/dev/null || true; } |
while read -r file; do   # (none left on a second run)
  sed -i -e "s#/opt/python/[^;\"]*/include/python3\.[0-9]*#$py_include#g" \
         -e "s#/opt/python/[^;\"]*/site-packages/numpy/_core/include#$np_include#g" "$file"
done
export AMENT_PREFIX_PATH="$venv${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
export CMAKE_PREFIX_PATH="$venv${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}"
export PATH="$venv/bin:$PATH"
cmake -S "$src" -B "$build" -DCMAKE_INSTALL_PREFIX="$venv" -DPython3_EXECUTABLE="$py" \
  -DBUILD_TESTING=OFF
cmake --build "$build" -j 2
cmake --install "$build"
"$py" -c 'from drill_sim_msgs.msg import BitMode, RunInfo, StringProfile, Telemetry, TopDriveCommand'
