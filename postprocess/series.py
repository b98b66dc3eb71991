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
    """Read one frame with meshio: points, point data, and the VTK_LINE cells of broken bonds.

    A frame in pieces (a .pvtu, output.parallel_frames: pieces on several MPI ranks) is read piece
    by piece and assembled as the gathered frame: owned points in global node order."""
    if vtu_path.endswith(".pvtu"):
        return _read_frame_in_pieces(vtu_path)
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


def _pieces_of(pvtu_path: str) -> list[str]:
    """The .vtu files a .pvtu names (Piece Source, relative to its folder)."""
    try:
        root = ET.parse(pvtu_path).getroot()
    except FileNotFoundError:
        raise PostprocessError(f"{pvtu_path}: no such file; rerun the solver (make case=<case>)") from None
    except ET.ParseError as error:
        raise PostprocessError(f"{pvtu_path}: not well-formed XML ({error}); was the solver interrupted?") from None
    if root.tag != "VTKFile" or root.get("type") != "PUnstructuredGrid":
        raise PostprocessError(f"{pvtu_path}: not a VTK PUnstructuredGrid (expected <VTKFile type=\"PUnstructuredGrid\">)")
    base = os.path.dirname(os.path.abspath(pvtu_path))
    pieces = [os.path.join(base, piece.get("Source", "")) for piece in root.iter("Piece")]
    if not pieces:
        raise PostprocessError(f"{pvtu_path}: names no piece; was the solver interrupted?")
    return pieces


def _read_frame_in_pieces(pvtu_path: str) -> Frame:
    """Every piece's owned points (vtkGhostType 0) placed at their node_id: the gathered frame's
    points and point data, bit for bit; each broken bond once (from the piece of its owned row)."""
    parts = []
    for piece in _pieces_of(pvtu_path):
        frame = read_frame(piece)
        for name in ("node_id", "vtkGhostType"):
            if name not in frame.point_data:
                raise PostprocessError(f"{piece}: a piece of {pvtu_path} without point data '{name}' "
                                       f"(pipeline/formats.md §4)")
        parts.append(frame)
    ids = [f.point_data["node_id"].astype(np.int64).reshape(-1) for f in parts]
    owned = [f.point_data["vtkGhostType"].reshape(-1) == 0 for f in parts]
    n = sum(int(o.sum()) for o in owned)
    node = np.concatenate([i[o] for i, o in zip(ids, owned)])
    if not np.array_equal(np.sort(node), np.arange(n)):
        raise PostprocessError(f"{pvtu_path}: its pieces do not own every node 0..{n - 1} once")
    order = np.argsort(node, kind="stable")
    names = [name for name in parts[0].point_data if name not in ("node_id", "vtkGhostType")]
    point_data = {}
    for name in names:
        if any(name not in f.point_data for f in parts):
            raise PostprocessError(f"{pvtu_path}: point data '{name}' is not in every piece")
        point_data[name] = np.concatenate([f.point_data[name][o] for f, o in zip(parts, owned)])[order]
    points = np.concatenate([f.points[o] for f, o in zip(parts, owned)])[order]
    lines = [i[f.broken_bonds] for f, i in zip(parts, ids) if len(f.broken_bonds)]
    broken = np.concatenate(lines) if lines else np.zeros((0, 2), dtype=np.int64)
    first = parts[0]
    return Frame(path=pvtu_path, points=points, point_data=point_data, broken_bonds=broken,
                 time=first.time, step=first.step)
