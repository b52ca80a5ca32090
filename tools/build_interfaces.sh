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
#
# Then tf2 (tf2, tf2_msgs, tf2_py, tf2_ros_py: no wheel holds them; `pose_source: tf` needs
# tf2_ros) from ROS 2 Jazzy's geometry2 sources, with colcon, into the same prefix: from the
# checkout --geometry2 DIR names, else from ../shared/deps/geometry2-jazzy-tf2.tar.gz beside
# this repository; skipped when tf2_ros imports already (a ROS install), and said so when no
# source can be had (the node runs on `pose_source: topic` without it).
#
#   bash tools/build_interfaces.sh [--force] [--geometry2 DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
python=${PYTHON:-python3}
force=0
geometry2=""
archive=$root/../shared/deps/geometry2-jazzy-tf2.tar.gz
while [ $# -gt 0 ]; do
  case $1 in
    --force) force=1 ;;
    --geometry2) [ $# -ge 2 ] || { echo "build_interfaces: --geometry2 needs a folder" >&2; exit 2; }
                 geometry2=$(cd "$2" 2>/dev/null && pwd) \
                   || { echo "build_interfaces: --geometry2 $2: no such folder" >&2; exit 2; }
                 shift ;;
    *) echo "build_interfaces: unknown argument '$1' (usage: $0 [--force] [--geometry2 DIR])" >&2; exit 2 ;;
  esac
  shift
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

# tf2 from geometry2's sources (a checkout, else the archive), with colcon, merged into the prefix
build_tf2() {
  local build=$root/build/tf2 stamp=$prefix/share/tf2_ros_py/active_recognition.stamp sum start src
  if [ -n "$geometry2" ]; then
    src=$geometry2
  elif [ -f "$archive" ]; then
    src=$archive
  fi
  if [ ! -f "$stamp" ] && "$python" -c "import tf2_ros" 2>/dev/null; then
    echo "build_interfaces: tf2_ros is installed already; nothing to build"
    return
  fi
  if [ -z "${src:-}" ]; then
    echo "build_interfaces: tf2 not built: no geometry2 source (--geometry2 DIR, a checkout of" \
         "ros2/geometry2 branch jazzy, or $archive); pose_source: tf needs it"
    return
  fi
  sum=$( (if [ -d "$src" ]; then (cd "$src" && find tf2 tf2_msgs tf2_py tf2_ros_py -type f | sort | xargs cat); \
          else cat "$src"; fi; cat "$root"/tools/build_interfaces.sh; "$python" -VV) | sha256sum | cut -d' ' -f1)
  if [ "$force" = 0 ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$sum" ] && "$python" -c "import tf2_ros" 2>/dev/null; then
    echo "build_interfaces: tf2 up to date in $prefix"
    return
  fi
  local colcon
  colcon=$(dirname "$executable")/colcon
  [ -x "$colcon" ] || { echo "build_interfaces: tf2 needs colcon (pip install -e '.[ros,test]')" >&2; exit 1; }
  rm -rf "$build" && mkdir -p "$build/src"
  if [ -d "$src" ]; then
    cp -r "$src"/tf2 "$src"/tf2_msgs "$src"/tf2_py "$src"/tf2_ros_py "$build/src/"
  else
    tar xzf "$src" -C "$build/src"
  fi
  start=$(date +%s)
  (cd "$build" && "$colcon" --log-base log build --base-paths src --build-base colcon \
     --packages-select tf2_msgs tf2 tf2_py tf2_ros_py --merge-install --install-base "$prefix" \
     --cmake-args -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF -DPython3_EXECUTABLE="$executable" \
       -DCMAKE_PROJECT_INCLUDE="$root/tools/interfaces_wheels.cmake" >build.log 2>&1) \
    || { tail -40 "$build/build.log" >&2; echo "build_interfaces: tf2 failed; the log: $build/build.log" >&2; exit 1; }
  echo "$sum" >"$stamp"
  "$python" -c "import tf2_ros" || { echo "build_interfaces: tf2 built, but tf2_ros does not import" >&2; exit 1; }
  echo "build_interfaces: tf2 built in $(($(date +%s) - start)) s into $prefix"
}

build_tf2
