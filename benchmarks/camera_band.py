# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Where the camera's known accuracy goes: the elevation band, then the camera itself.

A camera over the floor an object stands on never looks from below (the node's default limits,
elevation 0 to 90 degrees); the render figures of benchmarks/open_set_auroc.py come from the whole
sphere, the paper's setting. Three committed outputs of the same model and stored `unknown`
answer, episodes cut after 3 / 6 / 9 views, split the gap: renders on the whole sphere
(open_set.json), renders in the band (open_set_band.json: `open_set_auroc.py --min-elevation 0`), and
the RealSense-like camera in the band (open_set_camera.json). Writes
docs/results/modelnet10/camera_band.json; the last line is JSON.

    python benchmarks/open_set_auroc.py --dataset modelnet --root DIR --min-elevation 0 \
        --out docs/results/modelnet10/open_set_band.json
    python benchmarks/camera_band.py
"""
import argparse
import json
from pathlib import Path

from common import emit, one_line_errors, results_dir

from active_recognition.argument_checks import InputError
from active_recognition.evaluation.report import write_json

VIEWS = ("3", "6", "9")


def known_accuracy(record, name):
    """{views: known accuracy} at the stored answer, cut after 3 / 6 / 9 views: an open_set_auroc.py
    record's `stored`, an open_set_camera.py record's `cut`."""
    part = record.get("stored") or record.get("cut")
    if not part or "known_accuracy" not in part:
        raise InputError(f"{name}: no stored known accuracy (open_set_auroc.py's 'stored' or "
                         "open_set_camera.py's 'cut')")
    return {v: part["known_accuracy"][v] for v in VIEWS}


def split_gap(sphere, band, camera):
    """{views: points} lost to the band (sphere - band), to the camera (band - camera) and in all
    (sphere - camera): the first two add up to the third."""
    def points(a, b):
        return {v: round(100 * (a[v] - b[v]), 2) for v in VIEWS}
    return {"band": points(sphere, band), "camera": points(band, camera), "total": points(sphere, camera)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    folder = results_dir("modelnet")
    ap.add_argument("--sphere", default=str(folder / "open_set.json"), help="open_set_auroc.py on the whole sphere")
    ap.add_argument("--band", default=str(folder / "open_set_band.json"), help="open_set_auroc.py --min-elevation 0")
    # --camera and --out by hand: --camera is open_set_camera.py's JSON (not a preset); --out has a fixed default
    ap.add_argument("--camera", default=str(folder / "open_set_camera.json"), help="open_set_camera.py")
    ap.add_argument("--out", default=str(folder / "camera_band.json"), help="JSON ('' = none)")
    args = ap.parse_args(argv)
    with one_line_errors(ap):
        records = {}
        for key in ("sphere", "band", "camera"):
            path = Path(getattr(args, key))
            if not path.is_file():
                raise InputError(f"--{key} {path}: no such file")
            records[key] = json.loads(path.read_text())
        if records["band"].get("min_elevation") != 0.0:
            raise InputError(f"--band {args.band}: not run with --min-elevation 0 "
                             f"(min_elevation {records['band'].get('min_elevation')!r})")
        if records["sphere"].get("min_elevation", -90.0) != -90.0:  # open_set_auroc.py before the key: the sphere
            raise InputError(f"--sphere {args.sphere}: not a whole-sphere run "
                             f"(min_elevation {records['sphere']['min_elevation']!r})")
        for key in ("checkpoint", "planner"):  # the same model and planner, or the split means nothing
            seen = {name: r.get(key) for name, r in records.items()}
            if len(set(seen.values())) > 1:
                raise InputError(f"the three records are of different {key}s: "
                                 + ", ".join(f"--{name} {value!r}" for name, value in seen.items()))
        acc = {k: known_accuracy(r, getattr(args, k)) for k, r in records.items()}
        record = {"checkpoint": records["camera"].get("checkpoint"), "known_accuracy": acc,
                  "objects": {"sphere": records["sphere"]["objects"]["known_test"],
                              "band": records["band"]["objects"]["known_test"],
                              "camera": records["camera"].get("objects")},
                  "points_lost": split_gap(acc["sphere"], acc["band"], acc["camera"])}
        if args.out:
            write_json(Path(args.out), record)
        emit(record["points_lost"])


if __name__ == "__main__":
    main()
