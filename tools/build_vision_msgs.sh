#!/usr/bin/env bash
# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

# The former name of tools/build_interfaces.sh, kept for old commands: it builds vision_msgs and
# then active_recognition_interfaces into the Python environment of the PyPI ROS wheels.
exec bash "$(dirname "$0")/build_interfaces.sh" "$@"
