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


def build_parser():
    parser = argparse.ArgumentParser(prog="active-recognition", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    for add in ADDERS:
        add(sub)
    return parser


ADDERS = [add_render]


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        return args.func(args) or 0
    except (ValueError, FileNotFoundError) as e:  # MeshError, bad options, missing files
        print(f"active-recognition {args.command}: error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
