# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The model layer: the network, its episode and its view planners.

network (encoder, recurrent cell, heads), ensemble (networks answering as one), episode (the
loop of views, B episodes at once, in autograd), policies (the next-view planners: learned,
random, fixed, imitation, ...), size_prior (the object's size as class evidence) and checkpoint
(files as plain dicts, loaded with weights_only). Imports sensing, unknown (scores, thresholds)
and the top-level argument_checks and atomic_files."""
