"""Run the preprocessing stage alone:

    python3 -m preprocess MESH -o nodes.vtu --dim 2 --thickness 1e-3 --method lattice --dx 5e-4 \\
        --block plate [--block insert ...] [--layer left=1.5e-3 ...]
"""
from __future__ import annotations

import argparse
import sys
import warnings

from .build import build_node_cloud
from .discretize import METHODS
from .errors import PreprocessError
from .node_file import write_node_file


def _layer(text: str) -> tuple[str, float]:
    name, sep, value = text.partition("=")
    if not sep:
        raise argparse.ArgumentTypeError(f"expected NAME=METRES, got '{text}'")
    try:
        return name, float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{value}' is not a number (in '{text}')") from None


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m preprocess", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("mesh", help="mesh file (.msh or .unv)")
    parser.add_argument("-o", "--output", required=True, help="node file to write (.vtu)")
    parser.add_argument("--dim", type=int, choices=(2, 3), required=True, help="spatial dimension")
    parser.add_argument("--thickness", type=float, default=None, help="plate thickness [m] (2D)")
    parser.add_argument("--method", choices=METHODS, default="lattice")
    parser.add_argument("--dx", type=float, default=None, help="lattice spacing [m]")
    parser.add_argument("--block", action="append", required=True,
                        help="block name (a physical group of the top dimension); repeat, in order")
    parser.add_argument("--layer", action="append", type=_layer, default=[],
                        help="NAME=METRES: layer of a lower-dimension node set; repeatable")
    args = parser.parse_args(argv)
    warnings.showwarning = lambda message, *rest, **kw: print(f"warning: {message}", file=sys.stderr)
    try:
        cloud = build_node_cloud(args.mesh, dimension=args.dim, thickness=args.thickness, method=args.method,
                                 dx=args.dx, block_names=args.block, set_layers=dict(args.layer))
        write_node_file(args.output, cloud)
    except PreprocessError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    counts = ", ".join(f"{name} ({int(mask.sum())})" for name, mask in cloud.sets.items())
    print(f"{args.output}: {len(cloud.volume)} nodes, grid spacing {cloud.grid_spacing:.6g} m, "
          f"total volume {cloud.volume.sum():.6g} m^3, node sets: {counts or 'none'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
