# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Active object recognition with a recurrent 3D attentional network (Liu et al., 2019)."""
__version__ = "0.1.0"
