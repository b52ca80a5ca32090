# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Rebuild the real unknown objects of active_recognition/datasets/real_unknowns.tsv as PLY files.

    python tools/fetch_real_unknowns.py --out ~/data/real_unknowns [--mirrors /work/.mirror] [--manifest PATH]

Each file of an object is read from a local git mirror, <mirrors>/<owner>+<name>/repo (bare, or a
clone: repo/.git), where there is one (git cat-file blob), else downloaded from
raw.githubusercontent.com at the manifest's commit; its git blob hash must be the manifest's, or
the object is refused. The files are loaded with trimesh (.dae needs pycollada), scaled by their
`unit` into metres and merged, and written as one binary PLY,
<out>/<split>/<class>/<repository>__<object>.ply, through a temporary file renamed into place.
Objects already written are skipped. Prints, per split and class, the objects written,
skipped and failed; exits 1 when any failed. Open the result with
active_recognition.datasets.real_unknowns.real_unknowns(out, split).
"""
import argparse
import hashlib
import importlib.util
import io
import logging
import subprocess
import sys
import urllib.parse
import urllib.request
from collections import Counter
from pathlib import Path

import trimesh

from active_recognition.argument_checks import InputError
from active_recognition.atomic_files import atomic_path
from active_recognition.datasets.real_unknowns import MANIFEST, ply_path, read_manifest

RAW = "https://raw.githubusercontent.com/{repo}/{commit}/{path}"
TIMEOUT = 60  # seconds per download


class Refused(Exception):
    """An object that cannot be rebuilt; the message names the file and why."""


def git_blob_hash(data: bytes) -> str:
    return hashlib.sha1(b"blob %d\0" % len(data) + data).hexdigest()


def mirror_dirs(mirrors, repo):
    """The git directories a repository's local mirror may be: <mirrors>/<owner>+<name>/repo, bare,
    or the .git of a clone there."""
    if mirrors is None:
        return []
    repo_dir = mirrors / repo.replace("/", "+") / "repo"
    return [d for d in (repo_dir, repo_dir / ".git") if (d / "objects").is_dir()]


def file_bytes(row, mirrors):
    """The bytes of a manifest row's file, from its repository's local mirror or downloaded;
    Refused when they cannot be had or their git blob hash is not the manifest's."""
    data = None
    for mirror in mirror_dirs(mirrors, row["repo"]):
        got = subprocess.run(["git", "--git-dir", str(mirror), "cat-file", "blob", row["blob"]], capture_output=True)
        if got.returncode == 0:
            data = got.stdout
            break
    if data is None:  # no mirror, or the mirror lacks the blob
        url = RAW.format(repo=row["repo"], commit=row["commit"], path=urllib.parse.quote(row["path"]))
        try:
            with urllib.request.urlopen(url, timeout=TIMEOUT) as r:
                data = r.read()
        except Exception as e:  # URLError, HTTPError, timeouts: all mean this file cannot be had
            raise Refused(f"{row['repo']}/{row['path']}: cannot download {url} ({e})") from None
    got = git_blob_hash(data)
    if got != row["blob"]:
        raise Refused(f"{row['repo']}/{row['path']}: git blob hash {got}, the manifest says {row['blob']}")
    return data


def build(rows, mirrors):
    """One object's files loaded, scaled into metres and merged: a trimesh.Trimesh."""
    parts = []
    for row in rows:
        data = file_bytes(row, mirrors)
        try:
            mesh = trimesh.load(io.BytesIO(data), file_type=row["path"].rsplit(".", 1)[-1].lower(), force="mesh")
        except Exception as e:  # trimesh raises many types for files it cannot read
            raise Refused(f"{row['repo']}/{row['path']}: unreadable ({e})") from None
        if len(mesh.faces) == 0:
            raise Refused(f"{row['repo']}/{row['path']}: no faces")
        parts.append(mesh.apply_scale(row["unit"]))
    return trimesh.util.concatenate(parts)


def objects(rows):
    """{(split, repo, object): its rows}, in the manifest's order; Refused when the rows of an
    object disagree on its class or near."""
    out = {}
    for row in rows:
        out.setdefault((row["split"], row["repo"], row["object"]), []).append(row)
    for key, group in out.items():
        if len({(r["class"], r["near"]) for r in group}) > 1:
            raise InputError(f"object {'/'.join(key)}: its rows give different classes or near")
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, type=Path, help="folder to write <split>/<class>/*.ply under")
    ap.add_argument("--mirrors", type=Path, help="folder of bare git mirrors, <owner>+<name>/repo")
    ap.add_argument("--manifest", type=Path, default=MANIFEST, help="manifest (default: the shipped one)")
    args = ap.parse_args(argv)
    out, mirrors = args.out.expanduser(), args.mirrors and args.mirrors.expanduser()
    if out.exists() and not out.is_dir():
        ap.error(f"--out {out} is not a directory")
    if mirrors is not None and not mirrors.is_dir():
        ap.error(f"--mirrors {mirrors}: no such directory")
    if not args.manifest.is_file():
        ap.error(f"--manifest {args.manifest}: no such file")
    try:
        todo = objects(read_manifest(args.manifest))
    except InputError as e:
        ap.error(str(e))
    dae = any(r["path"].lower().endswith(".dae") for rows in todo.values() for r in rows)
    if dae and importlib.util.find_spec("collada") is None:
        sys.exit("fetch_real_unknowns: the manifest has .dae files, which trimesh reads with pycollada: "
                 "pip install pycollada")
    logging.getLogger("trimesh").setLevel(logging.ERROR)  # textures the files name but we never need
    counts = {}
    for (split, repo, name), rows in todo.items():
        target = out / ply_path(rows[0])
        tally = counts.setdefault((split, rows[0]["class"]), Counter())
        if target.is_file():
            tally["skipped"] += 1
            continue
        try:
            mesh = build(rows, mirrors)
            with atomic_path(target) as tmp:
                tmp.write_bytes(mesh.export(file_type="ply", encoding="binary"))
            tally["written"] += 1
        except Refused as e:
            print(f"failed {split}/{rows[0]['class']}/{target.name}: {e}", file=sys.stderr)
            tally["failed"] += 1
    width = max([len(c) for _, c in counts] + [5])
    print(f"{'split':<5}  {'class':<{width}}  written  skipped  failed")
    for (split, cls), n in sorted(counts.items()):
        print(f"{split:<5}  {cls:<{width}}  {n['written']:>7}  {n['skipped']:>7}  {n['failed']:>6}")
    total = sum(counts.values(), Counter())
    print(f"{'total':<5}  {'':<{width}}  {total['written']:>7}  {total['skipped']:>7}  {total['failed']:>6}")
    return 1 if total["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
