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


"""How long the embedded benchmarks take to generate: every shape of both splits of procedural
(2,500) and twins (3,000) built from primitives, without the cache (what a first run pays once),
then read back from a fresh cache. The README's "generated in seconds" rests on this.
Timings: the median of --repeat runs, seconds. Last line: JSON."""
import argparse
import statistics
import tempfile
import time

from common import emit

from active_recognition.datasets import GENERATED


def seconds(fn, repeat):
    """(median seconds of `repeat` calls, what the last call returned)"""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        value = fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), value


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=3, help="runs per figure (the median is kept)")
    args = ap.parse_args()
    result = {}
    for name, make in GENERATED.items():
        for split in ("train", "test"):
            built, ds = seconds(lambda: make(split), args.repeat)
            with tempfile.TemporaryDirectory() as cache:
                make(split, cache_dir=cache)
                cached, _ = seconds(lambda: make(split, cache_dir=cache), args.repeat)
            print(f"{name:<10} {split:<5} {len(ds):>5} shapes: generated in {built:5.1f} s, "
                  f"read from the cache in {cached:4.2f} s")
            result[f"{name}_{split}_s"], result[f"{name}_{split}_cached_s"] = built, cached
        total = result[f"{name}_train_s"] + result[f"{name}_test_s"]
        print(f"{name:<10} both splits generated in {total:.1f} s")
        result[f"{name}_s"] = total
    emit(result)


if __name__ == "__main__":
    main()
