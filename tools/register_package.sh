#!/usr/bin/env bash
# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

# Register this package in the ament index of the Python environment that holds the PyPI ROS
# wheels, as colcon would in a workspace, so that `ros2 run active_recognition recognizer` and
# `ros2 launch active_recognition active_recognition.launch.xml` find it; tools/build_interfaces.sh
# runs it last. A pip editable install writes none of this (setup.py's data_files and setup.cfg's
# script_dir are colcon's):
#   share/ament_index/resource_index/packages/active_recognition   the marker, written last
#   share/active_recognition/{package.xml,launch/*,config/*}       links to this checkout's files
#                                                                  (setup.py's data_files)
#   lib/active_recognition/{recognizer,simulated_camera}           links to the console scripts
# and the prefix becomes AMENT_PREFIX_PATH of every Python the environment starts where nothing
# set it (nothing sourced: a .pth file in its site-packages, as the wheels' own bootstrapper sets
# LD_LIBRARY_PATH), so nothing needs sourcing. A package installed some other way (pip install ., a colcon workspace) keeps its own.
#
#   bash tools/register_package.sh
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
python=${PYTHON:-python3}
name=active_recognition
prefix=$("$python" -c 'import sys; print(sys.prefix)')
site=$("$python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
where=$("$python" -c "import $name, pathlib; print(pathlib.Path($name.__file__).parent.parent)" 2>/dev/null) \
  || { echo "register_package: $name does not import in $prefix (pip install -e . first)" >&2; exit 1; }
if [ "$where" != "$root" ]; then
  echo "register_package: $name is installed from $where, not this checkout; nothing to register"
  exit 0
fi
marker=$prefix/share/ament_index/resource_index/packages/$name
pth=$site/${name}_ament.pth
line='import os, sys; os.environ.get("AMENT_PREFIX_PATH") or os.environ.__setitem__("AMENT_PREFIX_PATH", sys.prefix)'
# one link a file, as colcon --symlink-install makes them: ros2 launch looks for a launch file
# with os.walk, which does not enter a linked folder
links=("share/$name/package.xml=$root/package.xml")
for file in "$root"/launch/*.launch.xml "$root"/launch/*.launch.py "$root"/config/*.yaml "$root"/config/*.xml; do
  links+=("share/$name/${file#"$root"/}=$file")
done
for exe in recognizer simulated_camera; do
  [ -x "$prefix/bin/$exe" ] || { echo "register_package: $prefix/bin/$exe is missing (pip install -e . first)" >&2; exit 1; }
  links+=("lib/$name/$exe=$prefix/bin/$exe")
done
# the links there now, against those above: any missing, changed or stale (a file renamed or gone)
# (in a fresh environment neither folder exists: find fails, and under pipefail so would this)
there=$({ find "$prefix/share/$name" "$prefix/lib/$name" -type l 2>/dev/null || true; } | while read -r l; do
          echo "${l#"$prefix"/}=$(readlink "$l")"; done | sort)
wanted=$(printf '%s\n' "${links[@]}" | sort)
if [ "$there" = "$wanted" ] && [ -f "$marker" ] && [ "$(cat "$pth" 2>/dev/null)" = "$line" ]; then
  echo "register_package: $name up to date in $prefix's ament index"
  exit 0
fi
rm -f "$marker"  # while the rest is written, the package is not registered
rm -rf "${prefix:?}/share/$name" "${prefix:?}/lib/$name"
for link in "${links[@]}"; do
  path=$prefix/${link%%=*}
  mkdir -p "$(dirname "$path")"
  rm -rf "$path" && ln -s "${link#*=}" "$path"
done
echo "$line" >"$pth.tmp" && mv "$pth.tmp" "$pth"
mkdir -p "$(dirname "$marker")" && cp "$root/resource/$name" "$marker"
echo "register_package: $name registered in $prefix's ament index (ros2 run, ros2 launch), the" \
     "prefix its Pythons' AMENT_PREFIX_PATH where none is set"
