# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""A training batch's inputs, made ahead: while the network works on batch b, a thread of its
own draws batch b + 1's augmented cameras and renders what the network does not change
(pre-training's images, imitation's 50 candidates). Each batch draws from its own seeded
generator in the order it would without (Trainer.inputs), so the batches are the same, bit for
bit; embree and numpy's large operations release the GIL, so the work overlaps the network's."""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor


class Ahead:
    """make(b) for each batch b asked, the one after it made on a thread meanwhile."""

    def __init__(self, make, enabled=True):
        self.make, self.pending = make, {}
        self.pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="ahead") if enabled else None

    def get(self, b, following=None):
        """Batch b's inputs (made now unless made ahead), and `following`'s started."""
        made = self.pending.pop(b, None)
        out = made.result() if made is not None else self.make(b)
        if self.pool is not None and following is not None and following not in self.pending:
            self.pending[following] = self.pool.submit(self.make, following)
        return out

    def close(self):
        """Wait for what is under way and let the thread go."""
        if self.pool is not None:
            self.pool.shutdown(wait=True)
