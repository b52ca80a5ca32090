# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0


"""How long datasets take to load, and what they hold in memory.

Without --dataset: the embedded benchmarks, every shape of both splits of procedural (2,500) and
twins (3,000) built from primitives without the cache (what a first run pays once), then read
back from a fresh cache. The README's "generated in seconds" rests on this. Timings: the median
of --repeat runs, seconds.

With --dataset modelnet|shapenet|folder --root DIR: both splits opened as train and evaluate open
them, each phase in a process of its own: cold (every mesh file parsed and normalised into an
empty conversion cache), then warm (the same from the cache), and the resident memory (RSS) of
what training keeps: both splits' meshes and one ray-casting scene (DepthCamera) per training
shape. Counts: files loaded, converted and skipped by reason. The OFF files themselves may sit in
the system's page cache (the disk is not measured, only parsing and conversion).

Last line: JSON."""
import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import add_common_flags, emit, one_line_errors

from active_recognition.datasets import GENERATED, open_splits

FILE_DATASETS = ("modelnet", "shapenet", "folder")


def seconds(fn, repeat):
    """(median seconds of `repeat` calls, what the last call returned)"""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        value = fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), value


def generated(args):
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
    return result


def rss_mb():
    """The resident memory of this process now, MiB."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2 ** 20


def phase(args):
    """One phase in this process: open both splits through the cache (cold or warm); when warm,
    then build a scene per training shape. Prints the figures as a JSON line."""
    from active_recognition.sensing.depth_layer import CameraConfig
    from active_recognition.training.train import Shapes

    start_rss, start, cpu = rss_mb(), time.perf_counter(), time.process_time()
    splits = open_splits(args.dataset, args.root, ("train", "val", "test"), cache_dir=args.cache_dir)
    out = {"load_s": time.perf_counter() - start, "load_cpu_s": time.process_time() - cpu}
    # the dataset's own splits: its training split is train and val together, read once
    for s, parts in (("train", ("train", "val")), ("test", ("test",))):
        meshes = [m for p in parts for m in map(splits[p].mesh, range(len(splits[p])))]
        ds = splits[parts[0]]
        out[s] = {"files": len(meshes) + len(ds.skipped), "loaded": len(meshes),
                  "converted": ds.loaded["converted"], "from_cache": ds.loaded["cache"],
                  "skipped": ds.skip_counts(), "skipped_files": sorted(p for p, _ in ds.skipped),
                  "vertices": sum(len(v) for v, _ in meshes),
                  "triangles": sum(len(f) for _, f in meshes),
                  "mesh_mb": round(sum(v.nbytes + f.nbytes for v, f in meshes) / 2 ** 20, 1)}
    if args.phase == "warm":
        out["rss_meshes_mb"] = rss_mb() - start_rss
        camera = CameraConfig(args.size, args.size, radius=args.radius)
        shapes, before, start = Shapes(splits["train"], camera), rss_mb(), time.perf_counter()
        shapes.cameras(range(len(shapes)))  # one scene per shape training learns from (train less val)
        out["scenes"] = len(shapes)
        out["scenes_build_s"] = time.perf_counter() - start
        out["rss_train_scenes_mb"] = rss_mb() - before
        out["rss_total_mb"] = rss_mb()
        out["rss_peak_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2 ** 10
    print(json.dumps(out))


def run_phase(args, name, cache):
    """Figures of one phase, run in a fresh process (so memory and caches start clean)."""
    cmd = [sys.executable, __file__, "--dataset", args.dataset, "--root", str(args.root),
           "--cache-dir", str(cache), "--phase", name, "--size", str(args.size),
           "--radius", str(args.radius)]
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, text=True)
    if proc.returncode:  # its one-line error (a bad root) is on stderr already: no second traceback
        sys.exit(proc.returncode)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def file_dataset(args):
    cache = Path(args.cache_dir) if args.cache_dir else Path(tempfile.mkdtemp(prefix="ar-cache-"))
    if cache.exists() and any(cache.iterdir()):
        sys.exit(f"dataset_generation: --cache-dir {cache} is not empty: a cold load needs an "
                 f"empty cache")
    try:
        cold = run_phase(args, "cold", cache)
        warm = run_phase(args, "warm", cache)
        cache_mb = sum(p.stat().st_size for p in cache.rglob("*") if p.is_file()) / 2 ** 20
    finally:
        if not args.cache_dir:
            shutil.rmtree(cache, ignore_errors=True)
    for s in ("train", "test"):
        c = cold[s]
        print(f"{args.dataset} {s:<5} {c['files']:>5} files: {c['loaded']} loaded, skipped "
              f"{sum(c['skipped'].values())} {c['skipped'] or ''}; {c['vertices']:,} vertices, "
              f"{c['triangles']:,} triangles, {c['mesh_mb']:.0f} MiB as float32/int32")
    print(f"cold load (empty cache) {cold['load_s']:.1f} s ({cold['load_cpu_s']:.1f} s of CPU), "
          f"warm {warm['load_s']:.1f} s ({warm['load_cpu_s']:.1f} s of CPU); cache {cache_mb:.0f} "
          f"MiB")
    print(f"RSS: meshes of both splits {warm['rss_meshes_mb']:.0f} MiB, plus "
          f"{warm['rss_train_scenes_mb']:.0f} MiB for the {warm['scenes']} training "
          f"scenes (built in {warm['scenes_build_s']:.1f} s); process {warm['rss_total_mb']:.0f} "
          f"MiB, peak {warm['rss_peak_mb']:.0f} MiB")
    return {"dataset": args.dataset, "cold_s": cold["load_s"], "cold_cpu_s": cold["load_cpu_s"],
            "warm_s": warm["load_s"], "warm_cpu_s": warm["load_cpu_s"], "cache_mb": cache_mb,
            "load_average": os.getloadavg()[0],
            "camera": f"{args.size}x{args.size}, radius {args.radius}",
            **{k: warm[k] for k in ("rss_meshes_mb", "rss_train_scenes_mb", "scenes", "scenes_build_s",
                                    "rss_total_mb", "rss_peak_mb")},
            **{s: {k: cold[s][k] for k in ("files", "loaded", "skipped", "skipped_files",
                                           "vertices", "triangles", "mesh_mb")}
               for s in ("train", "test")},
            "warm_from_cache": warm["train"]["from_cache"] + warm["test"]["from_cache"],
            "warm_converted": warm["train"]["converted"] + warm["test"]["converted"]}


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=3,
                    help="generated benchmarks: runs per figure (the median is kept)")
    ap.add_argument("--dataset", choices=FILE_DATASETS, default=None,
                    help="a dataset of mesh files to measure instead of the generated ones")
    add_common_flags(ap, "root")
    ap.add_argument("--cache-dir", default=None,
                    help="an empty folder for the conversion cache (default: a temporary one, "
                         "removed at the end)")
    ap.add_argument("--size", type=int, default=64, help="scenes: image height and width")
    ap.add_argument("--radius", type=float, default=1.0, help="scenes: viewing-sphere radius")
    ap.add_argument("--phase", choices=("cold", "warm"), default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    with one_line_errors(ap):
        if args.dataset is None:
            emit(generated(args))
        elif args.phase:
            phase(args)
        else:
            emit(file_dataset(args))


if __name__ == "__main__":
    main()
