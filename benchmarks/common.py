# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Helpers shared by the benchmarks (and by the tests that run ROS loops the same way): medians
of repeated timings, the last-line JSON, where each dataset's results go, the common flags (add_common_flags), one
line, not a traceback, for bad input, the recognizer's parameter for a shipped model, and stopping node
processes."""
import json
import os
import subprocess
import time
import warnings
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from active_recognition.argument_checks import InputError
from active_recognition.datasets import OPEN_SET
from active_recognition.evaluation.evaluate import EvalConfig
from active_recognition.model.checkpoint import shipped
from active_recognition.options.flags_and_parameters import add_flags
from active_recognition.simulation.depth_sensor import PRESETS

RESULTS = Path(__file__).resolve().parents[1] / "docs/results"
FOLDER = {"procedural": "", "twins": "twins", "modelnet": "modelnet10"}  # under docs/results


# A benchmark's own DDS domain when ROS_DOMAIN_ID is unset: above the test suite's (1-90,
# test/conftest.py), so a benchmark run beside the tests hears none of their nodes.
DOMAINS = (101, 200)


def private_domain(rng=None):
    """Set ROS_DOMAIN_ID to a random one of DOMAINS unless it is set; return it."""
    rng = np.random.default_rng() if rng is None else rng
    os.environ.setdefault("ROS_DOMAIN_ID", str(int(rng.integers(DOMAINS[0], DOMAINS[1] + 1))))
    return int(os.environ["ROS_DOMAIN_ID"])


def results_dir(dataset):
    """The folder of a dataset's committed results (procedural's are docs/results itself)."""
    return RESULTS / FOLDER[dataset]


def committed(path):
    """Whether `path` lies in docs/results, where the committed figures are."""
    return Path(path).resolve().is_relative_to(RESULTS.resolve())


def add_common_flags(ap, *names, root_required=False, starts=None, starts_help="seeded starts per object",
                     out=None):
    """The flags the benchmarks share, defined once, added to `ap` in the order named: --root and
    --checkpoint (evaluate's, EvalConfig; --root required where `root_required`), --camera (the
    simulated camera's preset, realsense by default), --starts (default `starts`) and --out (the
    JSON to write; `out` names its default file(s) in the help)."""
    for name in names:
        if name in ("root", "checkpoint"):
            required = {"root": {"required": True}} if name == "root" and root_required else {}
            add_flags(ap, EvalConfig, [name], **required)
        elif name == "camera":
            ap.add_argument("--camera", default="realsense", choices=sorted(PRESETS),
                            help="the simulated camera's preset")
        elif name == "starts":
            ap.add_argument("--starts", type=int, default=starts, help=f"{starts_help} (default {starts})")
        elif name == "out":
            ap.add_argument("--out", default=None, help=f"JSON to write ('' = none; default {out}; a partial "
                            "run must give it)")
        else:
            raise ValueError(f"add_common_flags: no common flag {name!r}")


def add_unknowns_flags(ap, default="unknowns"):
    """--unknowns (the objects of no known class: generated, or real meshes; `default` where a
    benchmark's headline is another) and --unknowns-root."""
    note = "" if default == "unknowns" else f" (here the default is {default}, which needs --unknowns-root)"
    ap.add_argument("--unknowns", default=default, choices=tuple(OPEN_SET),
                    help="the unknown objects: generated (unknowns) or real meshes (real_unknowns, under "
                    "--unknowns-root: tools/fetch_real_unknowns.py)" + note)
    ap.add_argument("--unknowns-root", default=None, help="real_unknowns' folder")


def output(ap, out, default, partial):
    """Where a run writes: `out` if given, else `default` (the committed figures), which a partial
    run (the flags named in `partial` set) may not overwrite: it must name its own --out."""
    if out is not None:
        return out
    if partial:
        ap.error(f"a partial run ({', '.join(partial)}) would overwrite the committed {default}: "
                 f"pass --out")
    return default


@contextmanager
def one_line_errors(ap):
    """Bad input (a root, a model file, an option the library refuses) ends the benchmark as
    argparse does: one line naming the thing and the reason, exit status 2."""
    try:
        yield
    except InputError as e:
        ap.error(str(e))


def median_ms(fn, repeat=30, warmup=3):
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times) * 1e3)


def paired_median_ms(fns, repeat=30, warmup=3):
    """Medians (ms) of several ways of doing the same work, timed in turn, one call of each per
    round: a drift in the machine's speed (other tenants, clocks) falls on all of them alike,
    where timing one after the other would charge it to whichever ran in the slow spell."""
    for _ in range(warmup):
        for fn in fns:
            fn()
    times = [[] for _ in fns]
    for _ in range(repeat):
        for fn, out in zip(fns, times):
            t = time.perf_counter()
            fn()
            out.append(time.perf_counter() - t)
    return [float(np.median(t) * 1e3) for t in times]


def emit(result):
    """Print the figures as the last line, JSON."""
    print(json.dumps({k: (round(v, 4) if isinstance(v, float) else v) for k, v in result.items()}))


def shipped_checkpoint(dataset="procedural"):
    """The recognizer's `checkpoint` parameter for a dataset's shipped model (its default is the
    ModelNet10 model: loops that show procedural or twins objects pass this)."""
    from rclpy.parameter import Parameter

    return Parameter("checkpoint", value=str(shipped(dataset)))


def stop_processes(procs, grace=10.0):
    """SIGTERM each node process (subprocess.Popen), wait up to `grace` seconds, then SIGKILL what
    is left. Once in many CI runs a camera process has outlived SIGTERM by 10 s inside FastDDS's
    teardown (its work long done): it is killed and reported, not left to fail the caller."""
    for p in procs:
        p.terminate()
    for p in procs:
        try:
            p.wait(timeout=grace)
        except subprocess.TimeoutExpired:
            warnings.warn(f"{p.args[:3]} outlived SIGTERM by {grace:g} s: killed")
            p.kill()
            p.wait(timeout=grace)


def show_object(executor, params, index, tries=3):
    """Set a camera's `index` parameter through `params` (an AsyncParameterClient), asking again
    up to `tries` times (idempotent: a response DDS dropped is asked for again): the response's
    SetParametersResults, or None where none came."""
    from rclpy.parameter import Parameter

    from active_recognition.nodes.demo import spin_until
    for _ in range(tries):
        done = params.set_parameters([Parameter("index", value=index)])
        if spin_until(executor, done.done, 10):
            return done.result().results
    return None
