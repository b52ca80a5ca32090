# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The runtime: what a robot runs, without ROS.

active_recognizer (one object: metric depth in, probabilities and the next view out), controller
(the node's episode loop: timestamped events in, controller_commands out), timing and view_waits
(how the loop waits and where its time went), robot_time (what views cost an arm), health (the
/diagnostics figures). Imports model, unknown, sensing and the top-level foundation modules;
never training, evaluation, datasets or simulation."""
