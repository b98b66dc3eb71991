"""The node file (pipeline/formats.md §1-2): a VTK XML UnstructuredGrid point cloud, raw appended data.

write_node_file writes it under a temporary name and renames it; read_node_file is our own
reader, which checks the header, every array's type, size and byte count, and the values.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from xml.sax.saxutils import quoteattr

import numpy as np

from common.atomic import atomic_path

from .cloud import NodeCloud
from .errors import PreprocessError

FORMAT_VERSION = 1
VTK_VERTEX = 1
DTYPES = {"Int32": "<i4", "Int64": "<i8", "UInt8": "u1", "Float64": "<f8", "UInt64": "<u8"}


def _arrays(cloud: NodeCloud):
    """(section, name, VTK type, components, little-endian array) in file order."""
    n = len(cloud.points)
    yield "FieldData", "pd_node_file_version", "Int32", 1, np.array([FORMAT_VERSION], "<i4")
    yield "FieldData", "dimension", "Int32", 1, np.array([cloud.dimension], "<i4")
    yield "FieldData", "grid_spacing", "Float64", 1, np.array([cloud.grid_spacing], "<f8")
    yield "Points", "Points", "Float64", 3, np.ascontiguousarray(cloud.points, "<f8")
    yield "Cells", "connectivity", "Int64", 1, np.arange(n, dtype="<i8")
    yield "Cells", "offsets", "Int64", 1, np.arange(1, n + 1, dtype="<i8")
    yield "Cells", "types", "UInt8", 1, np.full(n, VTK_VERTEX, "u1")
    yield "PointData", "volume", "Float64", 1, np.ascontiguousarray(cloud.volume, "<f8")
    yield "PointData", "block", "Int32", 1, np.ascontiguousarray(cloud.block, "<i4")
    for name, mask in cloud.sets.items():
        yield "PointData", f"set_{name}", "UInt8", 1, np.ascontiguousarray(mask, "u1")


def write_node_file(path: str, cloud: NodeCloud) -> None:
    """Write `cloud` to `path` atomically (temporary file in the same directory, then rename)."""
    problems = cloud.problems()
    if problems:
        raise PreprocessError(f"{path}: refusing to write an invalid node cloud: {'; '.join(problems)}")
    n = len(cloud.points)
    xml = {"FieldData": [], "Points": [], "Cells": [], "PointData": []}
    blobs = []
    offset = 0
    for section, name, vtype, ncomp, data in _arrays(cloud):
        raw = data.tobytes()
        attrs = f'type="{vtype}" Name={quoteattr(name)}'
        if section == "FieldData":
            attrs += ' NumberOfTuples="1"'
        if ncomp != 1:
            attrs += f' NumberOfComponents="{ncomp}"'
        xml[section].append(f'<DataArray {attrs} format="appended" offset="{offset}"/>')
        blobs.append(np.uint64(len(raw)).astype("<u8").tobytes())
        blobs.append(raw)
        offset += 8 + len(raw)

    def block(section, indent):
        pad = " " * indent
        return "".join(f"{pad}{line}\n" for line in xml[section])

    header = (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n'
        '  <UnstructuredGrid>\n'
        '    <FieldData>\n' + block("FieldData", 6) + '    </FieldData>\n'
        f'    <Piece NumberOfPoints="{n}" NumberOfCells="{n}">\n'
        '      <Points>\n' + block("Points", 8) + '      </Points>\n'
        '      <Cells>\n' + block("Cells", 8) + '      </Cells>\n'
        '      <PointData>\n' + block("PointData", 8) + '      </PointData>\n'
        '    </Piece>\n'
        '  </UnstructuredGrid>\n'
        '  <AppendedData encoding="raw">\n'
        '   _'
    )
    with atomic_path(path) as tmp, open(tmp, "wb") as stream:
        stream.write(header.encode("ascii"))
        for blob in blobs:
            stream.write(blob)
        stream.write(b"\n  </AppendedData>\n</VTKFile>\n")


def read_node_file(path: str) -> NodeCloud:
    """Read and validate a node file; PreprocessError (starting with `path`) on any problem."""
    def fail(message: str):
        raise PreprocessError(f"{path}: not a valid node file (pipeline/formats.md, section 2): {message}")

    try:
        with open(path, "rb") as stream:
            data = stream.read()
    except OSError as err:
        raise PreprocessError(f"{path}: cannot read: {err.strerror}") from err
    tag = data.find(b"<AppendedData")
    if tag < 0:
        fail("no <AppendedData> element (truncated file?)")
    close = data.find(b">", tag)
    underscore = data.find(b"_", close)
    if close < 0 or underscore < 0:
        fail("<AppendedData> has no '_' marking the start of the data (truncated file?)")
    try:
        root = ET.fromstring(data[:tag] + b"</VTKFile>")
        appended = ET.fromstring(data[tag:close + 1] + b"</AppendedData>")
    except ET.ParseError as err:
        fail(f"XML header: {err}")
    expected = {"type": "UnstructuredGrid", "byte_order": "LittleEndian", "header_type": "UInt64"}
    if root.tag != "VTKFile":
        fail(f"root element is <{root.tag}>, expected <VTKFile>")
    for key, value in expected.items():
        if root.get(key) != value:
            fail(f'VTKFile {key}="{root.get(key)}", expected "{value}"')
    if root.get("compressor"):
        fail(f'compressed data ({root.get("compressor")}) is not allowed')
    if appended.get("encoding") != "raw":
        fail(f'AppendedData encoding="{appended.get("encoding")}", expected "raw"')
    grid = root.find("UnstructuredGrid")
    pieces = grid.findall("Piece") if grid is not None else []
    if len(pieces) != 1:
        fail(f"expected one <Piece>, found {len(pieces)}")
    piece = pieces[0]
    try:
        n = int(piece.get("NumberOfPoints"))
        ncells = int(piece.get("NumberOfCells"))
    except (TypeError, ValueError):
        fail("<Piece> lacks NumberOfPoints/NumberOfCells")
    if n <= 0 or ncells != n:
        fail(f"NumberOfPoints = {n}, NumberOfCells = {ncells}: expected n > 0 vertex cells, one per point")
    base = underscore + 1

    def array(element, what: str, vtype: str, count: int) -> np.ndarray:
        if element is None:
            fail(f"missing {what}")
        if element.get("type") != vtype:
            fail(f"{what} has type {element.get('type')}, expected {vtype}")
        if element.get("format") != "appended":
            fail(f"{what} has format {element.get('format')}, expected appended")
        try:
            start = base + int(element.get("offset"))
        except (TypeError, ValueError):
            fail(f"{what} has no offset")
        if start + 8 > len(data):
            fail(f"{what}: data offset beyond the end of the file (truncated file?)")
        nbytes = int(np.frombuffer(data, "<u8", 1, start)[0])
        dtype = np.dtype(DTYPES[vtype])
        if nbytes != count * dtype.itemsize:
            fail(f"{what}: {nbytes} bytes, expected {count} values ({count * dtype.itemsize} bytes)")
        if start + 8 + nbytes > len(data):
            fail(f"{what}: the file ends inside the data (truncated file: {len(data)} bytes)")
        return np.frombuffer(data, dtype, count, start + 8).astype(dtype.newbyteorder("="))

    def named(parent, name):
        if parent is None:
            return None
        for e in parent.findall("DataArray"):
            if e.get("Name") == name:
                return e
        return None

    field = grid.find("FieldData")
    version = array(named(field, "pd_node_file_version"), "FieldData pd_node_file_version", "Int32", 1)[0]
    if version != FORMAT_VERSION:
        fail(f"pd_node_file_version = {version}; this reader knows version {FORMAT_VERSION}")
    dimension = int(array(named(field, "dimension"), "FieldData dimension", "Int32", 1)[0])
    if dimension not in (2, 3):
        fail(f"dimension = {dimension}, expected 2 or 3")
    grid_spacing = float(array(named(field, "grid_spacing"), "FieldData grid_spacing", "Float64", 1)[0])
    points_el = piece.find("Points/DataArray")
    if points_el is not None and points_el.get("NumberOfComponents") != "3":
        fail("Points must have NumberOfComponents=\"3\"")
    points = array(points_el, "Points", "Float64", 3 * n).reshape(n, 3)
    cells = piece.find("Cells")
    conn = array(named(cells, "connectivity"), "Cells connectivity", "Int64", n)
    offs = array(named(cells, "offsets"), "Cells offsets", "Int64", n)
    types = array(named(cells, "types"), "Cells types", "UInt8", n)
    if not (np.array_equal(conn, np.arange(n)) and np.array_equal(offs, np.arange(1, n + 1))
            and np.all(types == VTK_VERTEX)):
        fail("cells must be one VTK_VERTEX (type 1) per point, in point order")
    pdata = piece.find("PointData")
    volume = array(named(pdata, "volume"), "PointData volume", "Float64", n)
    block = array(named(pdata, "block"), "PointData block", "Int32", n)
    sets = {}
    for e in (pdata.findall("DataArray") if pdata is not None else []):
        name = e.get("Name") or ""
        if name.startswith("set_"):
            mask = array(e, f"PointData {name}", "UInt8", n)
            if np.any(mask > 1):
                fail(f"{name} holds values other than 0 and 1")
            sets[name[4:]] = mask.astype(bool)
    if not data[base:].rstrip().endswith(b"</VTKFile>"):
        fail("the file does not end with </VTKFile> (truncated file?)")
    cloud = NodeCloud(points=points, volume=volume, block=block, sets=sets, grid_spacing=grid_spacing,
                      dimension=dimension)
    problems = cloud.problems()
    if problems:
        fail("; ".join(problems))
    return cloud
