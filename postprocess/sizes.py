"""What a run left on disk, by kind: the line `make case=X` ends with (issue 39: "output size per
case printed"). Sizes are the files' own (st_size), in SI megabytes, so that the README's totals can
be checked with `du --apparent-size --block-size=1000000`-like arithmetic.

    /usr/bin/python3 -m postprocess.sizes out/membrane
    out/membrane: 12.4 MB: frames 9.8 MB (77 files), gmsh 1.9 MB, figures 0.6 MB (13 PNG), ...
"""
from __future__ import annotations

import os
import sys

# (kind, test on the path relative to the run folder), first match wins; the rest is "other".
KINDS = (
    ("frames", lambda rel: rel == "frames.pvd" or rel.startswith("frames" + os.sep)),
    ("gmsh", lambda rel: rel.startswith("gmsh" + os.sep)),
    ("figures", lambda rel: rel.startswith("figures" + os.sep)),
    ("history", lambda rel: rel in ("history.csv", "history.json", "run.log")),
    ("checkpoint", lambda rel: rel.startswith("checkpoint")),
    ("inputs", lambda rel: rel in ("case.json", "nodes.vtu", "mesh.msh") or rel.startswith("input" + os.sep)),
)


def output_sizes(out_dir: str) -> dict[str, tuple[int, int]]:
    """{kind: (bytes, files)} of every regular file under out_dir (symbolic links not followed,
    the folder's .lock left out), kinds in KINDS order, then "other" if any."""
    totals = {kind: [0, 0] for kind, _ in KINDS}
    other = [0, 0]
    for folder, dirs, files in os.walk(out_dir):
        dirs.sort()
        for name in files:
            path = os.path.join(folder, name)
            rel = os.path.relpath(path, out_dir)
            if rel == ".lock" or os.path.islink(path) or not os.path.isfile(path):
                continue
            size = os.stat(path).st_size
            entry = next((totals[kind] for kind, test in KINDS if test(rel)), other)
            entry[0] += size
            entry[1] += 1
    result = {kind: (b, n) for kind, (b, n) in totals.items() if n}
    if other[1]:
        result["other"] = (other[0], other[1])
    return result


def megabytes(size: int) -> str:
    return f"{size / 1e6:.1f} MB" if size >= 5e4 else f"{size / 1e3:.0f} kB"


def summary(out_dir: str) -> str:
    """One line: the total, then each kind with its size (and file count where it helps)."""
    sizes = output_sizes(out_dir)
    total = sum(b for b, _ in sizes.values())
    parts = []
    for kind, (size, files) in sizes.items():
        count = f" ({files} PNG)" if kind == "figures" else f" ({files} files)" if kind == "frames" else ""
        parts.append(f"{kind} {megabytes(size)}{count}")
    return f"{out_dir}: {megabytes(total)}" + (": " + ", ".join(parts) if parts else " (empty)")


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1 or not os.path.isdir(argv[0]):
        print("usage: python3 -m postprocess.sizes OUT_DIR (a run's output folder)", file=sys.stderr)
        return 2
    print(summary(argv[0]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
