# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Training, the harness's first half: losses, the trainer (train) and its options (train_config),
the learning-rate schedule, prefetch (a batch's inputs made ahead on a thread) and render_worker
(on a process), devices, outliers (outlier exposure), run_metrics (metrics.csv), visualize
(plots and pictures) and write_ensemble (several checkpoints as one). May import every layer
below it (datasets, simulation and options included); nothing a robot runs imports it."""
