"""Readers of the solver's frames (pipeline/formats.md §4): the frames.pvd collection and one frame .vtu."""
from __future__ import annotations

import dataclasses
import os
import xml.etree.ElementTree as ET

import numpy as np

from .errors import PostprocessError

REQUIRED_POINT_DATA = ("displacement", "damage")


def read_series(pvd_path: str) -> list[tuple[float, str]]:
    """(time [s], absolute .vtu path) of every frame listed in a .pvd collection, in time order.

    Paths in the .pvd are relative to its directory. A listed file that does not exist, a
    DataSet without `timestep` or `file`, or an empty collection is an error naming the .pvd.
    """
    try:
        root = ET.parse(pvd_path).getroot()
    except FileNotFoundError:
        raise PostprocessError(f"{pvd_path}: no such file; run the solver first (make case=<case>)") from None
    except ET.ParseError as error:
        line, column = error.position
        raise PostprocessError(f"{pvd_path}:{line}:{column}: not well-formed XML ({error}); "
                               f"was the solver interrupted while writing it?") from None
    if root.tag != "VTKFile" or root.get("type") != "Collection":
        raise PostprocessError(f"{pvd_path}: not a VTK collection (expected <VTKFile type=\"Collection\">)")
    base = os.path.dirname(os.path.abspath(pvd_path))
    series = []
    for number, dataset in enumerate(root.iter("DataSet")):
        time, file = dataset.get("timestep"), dataset.get("file")
        if time is None or file is None:
            raise PostprocessError(f"{pvd_path}: DataSet {number} lacks a 'timestep' or 'file' attribute")
        try:
            value = float(time)
        except ValueError:
            raise PostprocessError(f"{pvd_path}: DataSet {number}: timestep '{time}' is not a number") from None
        path = os.path.normpath(os.path.join(base, file))
        if file.endswith(".pvtu"):
            # output.parallel_frames: pieces (formats.md §4): one .vtu per MPI rank, with ghosts.
            raise PostprocessError(f"{pvd_path}: lists {file}, a frame in pieces (one .vtu per MPI rank, "
                                   f"output.parallel_frames: pieces), which postprocess does not read; "
                                   f"open frames.pvd in ParaView, or run the case again with "
                                   f"output.parallel_frames: gathered (the default)")
        if not os.path.isfile(path):
            raise PostprocessError(f"{pvd_path}: lists {file}, which does not exist ({path}); "
                                   f"rerun the solver (make case=<case>)")
        series.append((value, path))
    if not series:
        raise PostprocessError(f"{pvd_path}: the collection lists no frames; was the solver interrupted?")
    series.sort(key=lambda entry: entry[0])  # stable: equal times keep the file's order
    return series


@dataclasses.dataclass
class Frame:
    """One result frame. Points are reference positions [m]; broken_bonds holds node index pairs."""
    path: str
    points: np.ndarray                 # (N, 3) float64
    point_data: dict                   # name -> (N,) or (N, k) array
    broken_bonds: np.ndarray           # (M, 2) int64, each broken bond once
    time: float | None = None          # FieldData TIME [s], if present
    step: int | None = None            # FieldData step, if present

    @property
    def displacement(self) -> np.ndarray:
        return self.point_data["displacement"]

    @property
    def damage(self) -> np.ndarray:
        return self.point_data["damage"]


def read_frame(vtu_path: str) -> Frame:
    """Read one frame with meshio: points, point data, and the VTK_LINE cells of broken bonds."""
    # meshio's VTU reader itself: meshio.read() would call sys.exit on a malformed file
    from meshio import vtu  # imported here: the readers of history and series do not need it

    if not os.path.isfile(vtu_path):
        raise PostprocessError(f"{vtu_path}: no such file; rerun the solver (make case=<case>)")
    try:
        mesh = vtu.read(vtu_path)
    except Exception as error:  # meshio raises assorted types for a truncated or foreign file
        raise PostprocessError(f"{vtu_path}: cannot read as VTK XML UnstructuredGrid "
                               f"({type(error).__name__}: {error}); was the solver interrupted?") from None
    points = np.asarray(mesh.points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise PostprocessError(f"{vtu_path}: points have shape {points.shape}, expected (N, 3)")
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    # Frames store their fields as float32 by default (output.precision): every reader downstream
    # (maps, probe, Gmsh copy, validation) computes in float64, as it did before, so the only
    # difference is the storage's rounding.
    point_data = {name: np.asarray(values, dtype=np.float64) if np.issubdtype(np.asarray(values).dtype, np.floating)
                  else np.asarray(values) for name, values in mesh.point_data.items()}
    missing = [name for name in REQUIRED_POINT_DATA if name not in point_data]
    if missing:
        raise PostprocessError(f"{vtu_path}: point data lacks {', '.join(missing)}; "
                               f"has {', '.join(sorted(point_data)) or 'none'} (pipeline/formats.md §4); "
                               f"postprocess needs them: list them in output.fields")
    n = len(points)
    for name, values in point_data.items():
        if len(values) != n:
            raise PostprocessError(f"{vtu_path}: point data '{name}' has {len(values)} values for {n} points")
    displacement = point_data["displacement"]
    if displacement.ndim != 2 or displacement.shape[1] not in (2, 3):
        raise PostprocessError(f"{vtu_path}: 'displacement' has shape {displacement.shape}, expected ({n}, 3)")
    if displacement.shape[1] == 2:
        point_data["displacement"] = np.column_stack([displacement, np.zeros(n)])
    point_data["damage"] = point_data["damage"].reshape(n)

    lines = [block.data for block in mesh.cells if block.type == "line"]
    broken = np.concatenate(lines).astype(np.int64) if lines else np.zeros((0, 2), dtype=np.int64)
    if broken.size and (broken.min() < 0 or broken.max() >= n):
        raise PostprocessError(f"{vtu_path}: a broken-bond cell refers to a node outside 0..{n - 1}")

    def scalar(name):
        values = mesh.field_data.get(name)
        return None if values is None or np.size(values) == 0 else np.ravel(values)[0]

    time, step = scalar("TIME"), scalar("step")
    return Frame(path=vtu_path, points=points, point_data=point_data, broken_bonds=broken,
                 time=None if time is None else float(time), step=None if step is None else int(step))
