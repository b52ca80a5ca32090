# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The simulated depth camera's core (depth_sensor): a dataset's mesh in metres rendered as a
real camera sees it (K, noise, dropout, a floor, arm error). nodes/simulated_camera.py and the
benchmarks run it; the recognizer never imports it. Imports datasets and everything below."""
