"""Helpers shared by the benchmarks: medians of repeated timings, and the last-line JSON."""
import json
import time

import numpy as np


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
