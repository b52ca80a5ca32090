# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Active object recognition with a recurrent 3D attentional network (Liu et al., 2019).

A folder per layer, bottom to top: sensing, unknown, model, runtime, datasets, simulation, options,
training, evaluation, nodes; each imports only from those below it (test/test_layers.py declares
the order). The top level holds the foundation every layer may use (argument_checks, atomic_files)
and the commands on top of them all (cli, options_docs)."""
__version__ = "0.1.0"
