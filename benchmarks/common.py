# Copyright 2026 active_recognition maintainers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""Helpers shared by the benchmarks: medians of repeated timings, the last-line JSON, and where
each dataset's results go."""
import json
import time
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parents[1] / "docs/results"
FOLDER = {"procedural": "", "twins": "twins", "modelnet": "modelnet10"}  # under docs/results


def results_dir(dataset):
    """The folder of a dataset's committed results (procedural's are docs/results itself)."""
    return RESULTS / FOLDER[dataset]


def median_ms(fn, repeat=30, warmup=3):
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times) * 1e3)


def emit(result):
    """Print the figures as the last line, JSON."""
    print(json.dumps({k: (round(v, 4) if isinstance(v, float) else v) for k, v in result.items()}))
