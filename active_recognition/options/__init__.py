# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The options, each defined once as a dataclass field: flags_and_parameters (fields -> CLI flags
and ROS parameters), recognizer_params and camera_params (each node's parameters),
command_options (the CLI subcommands' options). The argument checks behind `option()` are the
top-level argument_checks; the docs generator is the top-level options_docs. recognizer_params
imports the runtime alone (no datasets, no simulated camera); camera_params and command_options
import datasets and simulation."""
