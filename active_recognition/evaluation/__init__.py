# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Evaluation, the harness's second half: evaluate (every planner on the same episodes),
camera_episodes (episodes through the simulated camera, as the node runs them),
shared_classifier (one multi-view classifier to judge every planner's views), view_sets (the
headroom a planner has), report (CSV, Markdown and plots). May import training and every layer
below; nothing a robot runs imports it."""
