"""A small solver output written exactly as pipeline/formats.md §1 and §4 say, with known values.

Frames are written by our own VTK XML writer (appended raw data, UInt64 headers, Int64
connectivity, vertex cells then one VTK_LINE per broken bond), independent of the postprocessor.
"""
from __future__ import annotations

import dataclasses
import json
import os
import pathlib

import numpy as np

DX = 1.0e-3          # m
OMEGA = 2.0e3        # rad/s: displacement oscillation
DECAY = 500.0        # 1/s: energy decay rate
FRAME_EVERY = 1.0e-4  # s

VTK_TYPES = {np.dtype(np.float64): "Float64", np.dtype(np.int64): "Int64", np.dtype(np.int32): "Int32",
             np.dtype(np.uint8): "UInt8"}


def write_vtu(path, points, point_data, field_data, broken_bonds):
    """VTK XML UnstructuredGrid in the encoding of formats.md §1."""
    n, m = len(points), len(broken_bonds)
    connectivity = np.concatenate([np.arange(n, dtype=np.int64), np.asarray(broken_bonds, np.int64).ravel()])
    offsets = np.concatenate([np.arange(1, n + 1, dtype=np.int64), n + 2 * np.arange(1, m + 1, dtype=np.int64)])
    types = np.concatenate([np.full(n, 1, np.uint8), np.full(m, 3, np.uint8)])
    broken_flag = np.concatenate([np.zeros(n, np.uint8), np.ones(m, np.uint8)])
    blobs, offset = [], 0

    def array(values, name=None, tuples=None):
        nonlocal offset
        values = np.ascontiguousarray(values)
        raw = values.astype(values.dtype.newbyteorder("<")).tobytes()
        blobs.append(np.uint64(len(raw)).tobytes() + raw)
        comps = values.shape[1] if values.ndim == 2 else 1
        attrs = f'type="{VTK_TYPES[values.dtype]}"'
        if name is not None:
            attrs += f' Name="{name}"'
        if comps > 1:
            attrs += f' NumberOfComponents="{comps}"'
        if tuples is not None:
            attrs += f' NumberOfTuples="{tuples}"'
        tag = f'<DataArray {attrs} format="appended" offset="{offset}"/>'
        offset += len(blobs[-1])
        return tag

    xml = ['<?xml version="1.0"?>',
           '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">',
           "<UnstructuredGrid>", "<FieldData>"]
    xml += [array(np.asarray([v]), k, 1) for k, v in field_data.items()]
    xml += ["</FieldData>", f'<Piece NumberOfPoints="{n}" NumberOfCells="{n + m}">', "<PointData>"]
    xml += [array(v, k) for k, v in point_data.items()]
    xml += ["</PointData>", "<CellData>", array(broken_flag, "broken_bond"), "</CellData>",
            "<Points>", array(np.asarray(points, np.float64)), "</Points>", "<Cells>",
            array(connectivity, "connectivity"), array(offsets, "offsets"), array(types, "types"),
            "</Cells>", "</Piece>", "</UnstructuredGrid>", '<AppendedData encoding="raw">']
    with open(path, "wb") as stream:
        stream.write(("\n".join(xml) + "\n_").encode())
        for blob in blobs:
            stream.write(blob)
        stream.write(b"\n</AppendedData>\n</VTKFile>\n")


def write_pvd(path, entries):
    """entries: (time, relative file) in the order they are listed."""
    lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             "<Collection>"]
    lines += [f'<DataSet timestep="{t!r}" group="" part="0" file="{f}"/>' for t, f in entries]
    lines += ["</Collection>", "</VTKFile>"]
    pathlib.Path(path).write_text("\n".join(lines) + "\n")


HISTORY_HEADER = ("step,time,dt,iterations,rejected,kinetic_energy,strain_energy,external_work,"
                  "damping_work,broken_bonds,wall_time")


def history_values(rows: int = 41, end: float = 5.0e-4) -> dict:
    """Known columns: a varying dt, K and rejections like an adaptive run, KE = cos²(ωt) e^{-λt}."""
    step = np.arange(rows, dtype=np.int64)
    time = np.linspace(0.0, end, rows)
    dt = np.concatenate([[0.0], np.diff(time)]) * (1.0 + 0.25 * np.sin(step))
    kinetic = np.cos(OMEGA * time) ** 2 * np.exp(-DECAY * time)
    strain = np.sin(OMEGA * time) ** 2 * np.exp(-DECAY * time)
    damping = 1.0 - np.exp(-DECAY * time)
    return {"step": step, "time": time, "dt": dt, "iterations": 1 + step % 4, "rejected": (step % 7 == 3).astype(np.int64),
            "kinetic_energy": kinetic, "strain_energy": strain, "external_work": 0.5 * time / end,
            "damping_work": damping, "broken_bonds": step // 10, "wall_time": 1.0e-3 * step}


def write_history(path, columns: dict):
    names = HISTORY_HEADER.split(",")
    with open(path, "w") as stream:
        stream.write(HISTORY_HEADER + "\n")
        for i in range(len(columns["step"])):
            stream.write(",".join(repr(columns[k][i].item()) for k in names) + "\n")


@dataclasses.dataclass
class SyntheticRun:
    out: pathlib.Path
    dimension: int
    times: np.ndarray                  # frame times [s]
    points: np.ndarray                 # (N, 3)
    displacements: list                # per frame (N, 3)
    damages: list                      # per frame (N,)
    broken: list                       # per frame (M, 2)
    history: dict
    centre: int                        # index of the node at the centre of the box

    @property
    def case_json(self):
        return self.out / "case.json"


def lattice(shape, dimension):
    axes = [DX * np.arange(k) for k in shape]
    if dimension == 2:
        x, y = np.meshgrid(*axes, indexing="xy")
        return np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    z, y, x = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")
    return np.column_stack([x.ravel(), y.ravel(), z.ravel()])


def make_run(out, *, dimension=2, shape=(9, 7), frames=6, figure_times=None, component=2):
    """Write case.json, history.csv, frames.pvd and frames/frame_NNNNNN.vtu into `out`."""
    out = pathlib.Path(out)
    (out / "frames").mkdir(parents=True)
    points = lattice(shape, dimension)
    n = len(points)
    centre_xyz = 0.5 * (points.min(axis=0) + points.max(axis=0))
    centre = int(np.argmin(np.linalg.norm(points - centre_xyz, axis=1)))
    times = FRAME_EVERY * np.arange(frames)
    x, y = points[:, 0], points[:, 1]
    width = np.ptp(x)
    bump = np.sin(np.pi * x / width) * np.sin(np.pi * y / max(np.ptp(y), DX))
    # the crack: bonds between the column left of the middle and the one right of it, one more row per frame
    nx = shape[0]
    middle_left = np.flatnonzero(np.isclose(x, DX * (nx // 2 - 1)) & np.isclose(points[:, 2], points[0, 2]))
    displacements, damages, broken, entries = [], [], [], []
    for k, t in enumerate(times):
        u = np.column_stack([1e-6 * np.sin(OMEGA * t) * bump, -2e-7 * t / times[-1] * x / width,
                             2e-4 * np.sin(OMEGA * t) * np.exp(-DECAY * t) * bump])
        cracked = middle_left[: max(0, k - 1)]
        bonds = np.column_stack([cracked, cracked + 1]).astype(np.int64)
        damage = np.zeros(n)
        damage[bonds.ravel()] = 0.125 + 0.01 * k
        v = np.gradient(u, axis=0)
        block = np.where(x < width / 2, 1, 2).astype(np.int32)
        name = f"frames/frame_{k:06d}.vtu"
        write_vtu(out / name, points, {"displacement": u, "velocity": v, "damage": damage, "block": block},
                  {"TIME": float(t), "step": np.int64(8 * k)}, bonds)
        displacements.append(u)
        damages.append(damage)
        broken.append(bonds)
        entries.append((float(t), name))
    write_pvd(out / "frames.pvd", entries)
    history = history_values(rows=8 * (frames - 1) + 1, end=float(times[-1]))
    write_history(out / "history.csv", history)
    case = {"format_version": 1, "case": out.name, "title": "synthetic test output (§5.1, façade)",
            "dimension": dimension, "grid_spacing": DX,
            "blocks": [{"id": 1, "name": "left", "model": "pmb"}, {"id": 2, "name": "right", "model": "pmb"}],
            "figures": {"times": figure_times, "displacement_component": component},
            "output": {"gmsh": "all"}}  # every frame into results.msh: what the Gmsh tests check
    (out / "case.json").write_text(json.dumps(case, indent=1))
    return SyntheticRun(out=out, dimension=dimension, times=times, points=points, displacements=displacements,
                        damages=damages, broken=broken, history=history, centre=centre)


def set_figures(run: SyntheticRun, times=None, component=None):
    """Rewrite case.json's `figures` entry."""
    case = json.loads(run.case_json.read_text())
    case["figures"]["times"] = times
    if component is not None:
        case["figures"]["displacement_component"] = component
    run.case_json.write_text(json.dumps(case, indent=1))


def png_size(path) -> tuple[int, int]:
    """Width and height from a PNG's IHDR chunk, after checking the signature."""
    data = pathlib.Path(path).read_bytes()[:24]
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    assert data[12:16] == b"IHDR"
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


def file_names(directory) -> list[str]:
    return sorted(os.listdir(directory))
