# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Sensing, the lowest layer: what a depth camera sees and where it may stand.

The viewing sphere and camera maths (geometry), the differentiable depth layer and its pixel
passes (depth_layer, depth_pixels), meshes, the reprojection of any depth camera into the
model's virtual one (reprojection), the views a robot can reach (reach), and the bounds a real
camera's input keeps (camera_input_bounds). Imports only the top-level argument_checks and
atomic_files."""
