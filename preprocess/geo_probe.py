"""Build a .geo's geometry with the gmsh API, without meshing it, and describe the body it makes.

    /usr/bin/python3 -m preprocess.geo_probe GEO DIMENSION '{"a": 0.005, ...}'   # prints JSON

pipeline/body.py runs this in a subprocess (gmsh keeps global state and a .geo may loop: a time
limit and a fresh process keep both away from the caller) after preprocess/geo_guard.py has checked
the .geo, so that a body that the parameters break (a hole larger than the plate, issue 17 item 10)
and a mesh that would take for ever (`lc: 2e-6`, item 11) are caught before gmsh meshes anything.

The JSON holds, for the top-dimension entities (surfaces of a 2D case, volumes of a 3D one):
  entities: [{tag, bbox, loops: [[curve or surface tags], ...], loop_boxes, loop_points}], loops[0]
    the outer boundary, loop_points (2D) each loop as a polygon [[x, y], ...];
  bbox: the union of their bounding boxes [xmin, ymin, zmin, xmax, ymax, zmax];
  groups: {name: [dim, number of entities]} of every physical group;
  errors: gmsh's error and warning lines while it read the geometry;
  numbers: the .geo's parameters as gmsh holds them (DefineConstant Name → value; a parameter given
    with -setnumber is not among them: its value is the case file's);
  size_options: Mesh.MeshSizeFactor, Mesh.MeshSizeMin and Mesh.MeshSizeMax as the .geo left them;
  boundary: {nodes, elements, size} of gmsh's mesh of the body's boundary (its curves in 2D, its
    surfaces in 3D; size the mean element size in m), made last, after everything above: a mesh size
    field (`Background Field`) or a point's size can make gmsh's mesh far finer than the case's mesh
    size says, and the boundary shows it in a small fraction of the whole mesh's time
    (pipeline/body.py check_mesh_growth extrapolates it to the body).
"""
from __future__ import annotations

import json
import sys


def _loops(gmsh, dim: int, tag: int) -> list[list[int]]:
    """The boundary of one entity split into its closed loops, in gmsh's order (the outer loop
    first: `Plane Surface(1) = {outer, hole, ...}`). Curves are chained through their end points;
    a 3D volume's surfaces are one loop per connected shell."""
    boundary = [t for _, t in gmsh.model.getBoundary([(dim, tag)], combined=False, oriented=True)]
    if dim == 2:
        loops, current, start = [], [], None
        for signed in boundary:
            ends = [p for _, p in gmsh.model.getBoundary([(1, abs(signed))], combined=False, oriented=False)]
            if len(ends) < 2:           # a closed curve (a full circle): a loop of its own
                if current:
                    loops.append(current)
                loops.append([signed])
                current, start = [], None
                continue
            first, last = (ends[0], ends[-1]) if signed > 0 else (ends[-1], ends[0])
            if not current:
                start = first
            current.append(signed)
            if last == start:
                loops.append(current)
                current, start = [], None
        if current:
            loops.append(current)
        return loops
    # Surfaces of a volume: group them into shells that share curves.
    shells: list[tuple[set[int], list[int]]] = []
    for signed in boundary:
        curves = {abs(c) for _, c in gmsh.model.getBoundary([(2, abs(signed))], combined=False)}
        joined = [s for s in shells if s[0] & curves]
        merged = (set(curves), [signed])
        for s in joined:
            merged[0].update(s[0])
            merged[1][:0] = s[1]
            shells.remove(s)
        shells.append(merged)
    return [s[1] for s in shells]


def _loop_points(gmsh, loop: list[int], per_curve: int = 32) -> list[list[float]]:
    """A closed loop of curves as a polygon [[x, y], ...]: each curve sampled at per_curve + 1
    parameter values (gmsh.model.getValue), in the loop's direction."""
    points: list[list[float]] = []
    for signed in loop:
        low, high = (b[0] for b in gmsh.model.getParametrizationBounds(1, abs(signed)))
        ts = [low + (high - low) * k / per_curve for k in range(per_curve + 1)]
        xyz = gmsh.model.getValue(1, abs(signed), ts)
        curve = [[xyz[3 * k], xyz[3 * k + 1]] for k in range(len(ts))]
        points += curve if signed > 0 else curve[::-1]
    return points


def _boundary_mesh(gmsh, dimension: int) -> dict:
    """Mesh the entities of dimension - 1 and measure their elements (corner nodes only)."""
    import numpy as np

    gmsh.model.mesh.generate(dimension - 1)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    if not len(tags):
        return {"nodes": 0, "elements": 0, "size": None}
    where = np.zeros(int(np.max(tags)) + 1, dtype=np.int64)
    where[np.asarray(tags, dtype=np.int64)] = np.arange(len(tags))
    xyz = np.asarray(coords, dtype=float).reshape(-1, 3)
    measures = []
    for etype, _, nodes in zip(*gmsh.model.mesh.getElements(dimension - 1)):
        count = gmsh.model.mesh.getElementProperties(etype)[3]
        corners = xyz[where[np.asarray(nodes, dtype=np.int64).reshape(-1, count)[:, :dimension]]]
        if dimension == 2:
            measures.append(np.linalg.norm(corners[:, 1] - corners[:, 0], axis=1))
        else:   # an equilateral triangle of side h has area √3/4 h²: the side of the mean area
            areas = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
            measures.append(np.sqrt(areas / (np.sqrt(3.0) / 4.0)))
    sizes = np.concatenate(measures) if measures else np.zeros(0)
    return {"nodes": len(tags), "elements": len(sizes), "size": float(sizes.mean()) if len(sizes) else None}


def probe(geo: str, dimension: int, parameters: dict[str, float]) -> dict:
    import gmsh

    argv = ["gmsh"]
    for name, value in parameters.items():
        argv += ["-setnumber", str(name), repr(float(value))]
    gmsh.initialize(argv, readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.logger.start()
        gmsh.open(geo)
        entities = []
        box = None
        for dim, tag in gmsh.model.getEntities(dimension):
            bbox = list(gmsh.model.getBoundingBox(dim, tag))
            loops = _loops(gmsh, dim, tag)
            loop_boxes = []
            for loop in loops:
                lb = None
                for t in loop:
                    b = gmsh.model.getBoundingBox(dim - 1, abs(t))
                    lb = list(b) if lb is None else [min(lb[i], b[i]) for i in range(3)] + \
                        [max(lb[i + 3], b[i + 3]) for i in range(3)]
                loop_boxes.append(lb)
            entity = {"tag": tag, "bbox": bbox, "loops": loops, "loop_boxes": loop_boxes}
            if dim == 2:
                entity["loop_points"] = [_loop_points(gmsh, loop) for loop in loops]
            entities.append(entity)
            box = bbox if box is None else [min(box[i], bbox[i]) for i in range(3)] + \
                [max(box[i + 3], bbox[i + 3]) for i in range(3)]
        groups = {}
        for dim, tag in gmsh.model.getPhysicalGroups():
            name = gmsh.model.getPhysicalName(dim, tag)
            groups[name or f"#{tag}"] = [dim, len(gmsh.model.getEntitiesForPhysicalGroup(dim, tag))]
        errors = [line for line in gmsh.logger.get() if line.startswith(("Error", "Warning"))]
        numbers = {p["name"]: p["values"][0] for p in json.loads(gmsh.onelab.get())["onelab"]["parameters"]
                   if p.get("type") == "number" and len(p.get("values", [])) == 1}
        size_options = {o: gmsh.option.getNumber(f"Mesh.{o}") for o in ("MeshSizeFactor", "MeshSizeMin", "MeshSizeMax")}
        boundary = _boundary_mesh(gmsh, dimension) if entities else None
        return {"entities": entities, "bbox": box, "groups": groups, "errors": errors, "numbers": numbers,
                "size_options": size_options, "boundary": boundary}
    finally:
        gmsh.finalize()


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    geo, dimension, parameters = args[0], int(args[1]), json.loads(args[2])
    print(json.dumps(probe(geo, dimension, parameters)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
