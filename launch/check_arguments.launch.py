# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Refuse a launch argument the including file does not declare: `ros2 launch` passes on any
NAME:=VALUE without a word, so a misspelt `pose_sorce:=topic` would otherwise be ignored. The
including file names its arguments in `declared` (space-separated), in an <include> of this file
with <arg name="declared" value="objects root ..."/>."""
import difflib

from launch import LaunchDescription
from launch.actions import OpaqueFunction


def check(context):
    declared = context.launch_configurations.get("declared", "").split()
    given = sorted(set(context.launch_configurations) - set(declared) - {"declared"})
    if given:
        said = []
        for name in given:
            close = difflib.get_close_matches(name, declared, n=1)
            said.append(f"{name!r}" + (f" (did you mean {close[0]!r}?)" if close else ""))
        raise RuntimeError(f"unknown launch argument {', '.join(said)}; this file takes: {', '.join(declared)}")
    return []


def generate_launch_description():
    # `declared` is read, not declared: declared, it would be listed by the including file's --show-args
    return LaunchDescription([OpaqueFunction(function=check)])
