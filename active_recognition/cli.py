"""The `active-recognition` command: one entry point, a subcommand per job."""
from __future__ import annotations

import argparse
import math
import sys


def cmd_render(args):
    import numpy as np

    from . import geometry
    from .depth_layer import CameraConfig, DepthCamera
    from .meshes import load_mesh
    from .visualize import depth_grid

    verts, faces = load_mesh(args.mesh)
    cfg = CameraConfig(height=args.size, width=args.size, radius=args.radius,
                       fov=None if args.fov is None else math.radians(args.fov))
    cam = DepthCamera(verts, faces, cfg)
    if args.views:
        views = geometry.fibonacci_views(args.views)
    else:
        views = np.array([[args.theta, args.phi]])
    depth = cam.render(views)
    titles = [f"({t:.2f}, {p:.2f})" for t, p in views]
    depth_grid(depth, args.out, titles=titles)
    hit = (depth < 255).mean()
    print(f"wrote {args.out}: {len(views)} view(s) {args.size}x{args.size}, "
          f"{100 * hit:.1f}% of pixels hit the mesh")


def add_render(sub):
    p = sub.add_parser("render", help="render depth images of a mesh file to a PNG")
    p.add_argument("--mesh", required=True, help="mesh file (.off .obj .ply .stl .glb)")
    p.add_argument("--theta", type=float, default=math.radians(60), help="polar angle, radians")
    p.add_argument("--phi", type=float, default=math.radians(30), help="azimuth, radians")
    p.add_argument("--views", type=int, default=0,
                   help="render this many evenly spread views instead of one")
    p.add_argument("--size", type=int, default=64, help="image height and width in pixels")
    p.add_argument("--radius", type=float, default=1.0, help="viewing-sphere radius R")
    p.add_argument("--fov", type=float, default=None,
                   help="field of view in degrees (default: holds the [-0.5, 0.5]^3 cube)")
    p.add_argument("--out", default="depth.png", help="output PNG")
    p.set_defaults(func=cmd_render)


def cmd_dataset(args):
    import numpy as np

    from .datasets import default_cache_dir, open_dataset
    from .depth_layer import DepthCamera
    from .visualize import depth_grid

    cache = None if args.no_cache else (args.cache_dir or default_cache_dir())
    splits = {s: open_dataset(args.name, args.root, s, cache_dir=cache) for s in ("train", "test")}
    classes = splits["train"].classes
    width = max(len(c) for c in classes)
    print(f"{args.name}: {len(classes)} classes")
    print(f"{'class':<{width}}  {'train':>6}  {'test':>6}")
    counts = {s: ds.class_counts() for s, ds in splits.items()}
    for i, c in enumerate(classes):
        print(f"{c:<{width}}  {counts['train'][i]:>6}  {counts['test'][i]:>6}")
    print(f"{'total':<{width}}  {len(splits['train']):>6}  {len(splits['test']):>6}")
    skipped = splits["train"].skipped + splits["test"].skipped
    print(f"skipped {len(skipped)} file(s)")
    for path, reason in skipped:
        print(f"  {path}: {reason}")
    if args.contact_sheet:
        ds, rng = splits["test"], np.random.default_rng(args.seed)
        views = geometry_views(args.views_per_object)
        images, labels = [], []
        for label, c in enumerate(classes):
            idx = np.flatnonzero(ds.labels() == label)
            for i in rng.choice(idx, min(args.objects_per_class, len(idx)), replace=False):
                images.extend(DepthCamera(*ds.mesh(i)).render(views))
            labels.append(c)
        depth_grid(np.array(images), args.contact_sheet,
                   columns=args.objects_per_class * len(views), row_labels=labels)
        print(f"wrote {args.contact_sheet}")


def geometry_views(n):
    """A few readable views: the first n of front, side, top, below, three-quarter."""
    import numpy as np
    views = [(1.57, -1.57), (1.57, 0.0), (0.35, -1.57), (2.6, -1.2), (1.0, -0.8)]
    return np.array(views[:max(1, min(n, len(views)))])


def add_dataset(sub):
    from .datasets import NAMES
    p = sub.add_parser("dataset", help="index a dataset: class counts, skipped files, contact sheet")
    p.add_argument("--name", choices=NAMES, default="procedural", help="dataset layout")
    p.add_argument("--root", default=None, help="dataset root folder (not for procedural)")
    p.add_argument("--cache-dir", default=None,
                   help="where parsed meshes are cached (default ~/.cache/active_recognition)")
    p.add_argument("--no-cache", action="store_true", help="do not read or write the cache")
    p.add_argument("--contact-sheet", default=None, help="write a PNG grid of test-split depth images")
    p.add_argument("--objects-per-class", type=int, default=2, help="objects per class on the sheet")
    p.add_argument("--views-per-object", type=int, default=3, help="views per object on the sheet")
    p.add_argument("--seed", type=int, default=0, help="which objects go on the sheet")
    p.set_defaults(func=cmd_dataset)


def build_parser():
    parser = argparse.ArgumentParser(prog="active-recognition", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    for add in ADDERS:
        add(sub)
    return parser


ADDERS = [add_render, add_dataset]


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        return args.func(args) or 0
    except (ValueError, FileNotFoundError) as e:  # MeshError, bad options, missing files
        print(f"active-recognition {args.command}: error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
