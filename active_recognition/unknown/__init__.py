# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The unknown answer, all of it: whether an object is of none of the known classes.

scores (msp, energy, prototypes, running means, AUROC and operating points), thresholds (the
`open_set` entry a checkpoint carries, checked on load), decision (when the recognizer answers
`unknown` and when a confident answer waits) and fit (`active-recognition open-set-fit`: fitting
the means and thresholds into a checkpoint). scores, thresholds and decision import only
argument_checks; fit is harness code and counts as the evaluation layer (it runs episodes), so
nothing a robot runs imports it."""
