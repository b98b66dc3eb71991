"""The part of the resolved case.json (pipeline/formats.md §3) that the postprocessor uses."""
from __future__ import annotations

import dataclasses
import json
import numbers

from .errors import PostprocessError

AXES = "xyz"
GMSH_CHOICES = ("all", "figures", "none")
# figures.dpi's default (pipeline/schema.py), also for a case.json written before the key existed,
# and the validation report's figures: fit for print.
DEFAULT_DPI = 300
DPI_RANGE = (50, 1200)   # pipeline/schema.py's range: below 50 text is unreadable, above 1200 a map is ~100 MB


@dataclasses.dataclass
class CaseSettings:
    name: str                       # `case`: shown in every title
    dimension: int                  # 2 or 3
    title: str = ""                 # one-line description, if the case has one
    grid_spacing: float | None = None   # dx [m]: sizes the markers of the maps
    times: list | None = None       # `figures.times` [s], or None for four frames spread over the run
    component: int = 0              # `figures.displacement_component`: 0, 1, 2 for x, y, z
    dpi: int = DEFAULT_DPI          # `figures.dpi`: the PNGs' resolution; the layout is in points
    block_names: dict = dataclasses.field(default_factory=dict)  # block id -> name, for Gmsh
    gmsh: str = "figures"           # `output.gmsh`: frames copied to gmsh/results.msh: all | figures | none
    integrator: str | None = None   # `time.integrator`: what timestep.png shows (None: not in case.json)
    breakable: bool = True          # some block has a fracture_energy: else no damage maps
    cracks: list = dataclasses.field(default_factory=list)  # `cracks`: pre-cracks as (from, to) [m]
    probe: list | str | None = None  # `figures.probe`: a point [m], a node-set name, or None (the centre)

    @property
    def heading(self) -> str:
        """The case's name, with its title when it has one."""
        return f"{self.name} ({self.title})" if self.title else self.name


def _is_number(value) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def load_case_settings(path: str) -> CaseSettings:
    """Read and check the keys postprocess needs; an error names the file and the key."""
    try:
        with open(path, encoding="utf-8") as stream:
            case = json.load(stream)
    except FileNotFoundError:
        raise PostprocessError(f"{path}: no such file; preprocess the case first (make case=<case>), "
                               f"or point to it with --case-json PATH") from None
    except json.JSONDecodeError as error:
        raise PostprocessError(f"{path}:{error.lineno}:{error.colno}: not valid JSON ({error.msg})") from None
    except (OSError, UnicodeDecodeError) as error:
        raise PostprocessError(f"{path}: cannot read: {error}") from None
    if not isinstance(case, dict):
        raise PostprocessError(f"{path}: expected a JSON object (pipeline/formats.md §3)")

    def fail(key, what):
        raise PostprocessError(f"{path}: {key}: {what} (pipeline/formats.md §3)")

    name = case.get("case")
    if not isinstance(name, str) or not name:
        fail("case", f"expected the case name, got {name!r}")
    dimension = case.get("dimension")
    if dimension not in (2, 3) or isinstance(dimension, bool):
        fail("dimension", f"expected 2 or 3, got {dimension!r}")
    title = case.get("title") or ""
    if not isinstance(title, str):
        fail("title", f"expected a string, got {title!r}")
    spacing = case.get("grid_spacing")
    if spacing is not None and not (_is_number(spacing) and spacing > 0):
        fail("grid_spacing", f"expected a length > 0 [m], got {spacing!r}")

    figures = case.get("figures") or {}
    if not isinstance(figures, dict):
        fail("figures", f"expected an object, got {figures!r}")
    times = figures.get("times")
    if times is not None:
        if not isinstance(times, list) or not times or not all(_is_number(t) for t in times):
            fail("figures.times", f"expected a non-empty list of times [s] or null, got {times!r}")
        times = [float(t) for t in times]
    component = figures.get("displacement_component", 0)
    if component not in (0, 1, 2) or isinstance(component, bool):
        fail("figures.displacement_component", f"expected 0, 1 or 2 (x, y, z), got {component!r}")
    dpi = figures.get("dpi", DEFAULT_DPI)
    if not (isinstance(dpi, int) and not isinstance(dpi, bool) and DPI_RANGE[0] <= dpi <= DPI_RANGE[1]):
        fail("figures.dpi", f"expected a whole number of dots per inch in [{DPI_RANGE[0]}, {DPI_RANGE[1]}], got {dpi!r}")
    output = case.get("output") or {}
    gmsh = output.get("gmsh", "figures") if isinstance(output, dict) else "figures"
    if gmsh not in GMSH_CHOICES:
        fail("output.gmsh", f"expected one of {', '.join(GMSH_CHOICES)}, got {gmsh!r}")
    probe = figures.get("probe")
    if probe is not None and not (isinstance(probe, str) and probe) and not (
            isinstance(probe, list) and len(probe) in (2, 3) and all(_is_number(c) for c in probe)):
        fail("figures.probe", f"expected a point [x, y] or [x, y, z] in m or a node-set name, got {probe!r}")
    if isinstance(probe, list):
        probe = [float(c) for c in probe] + [0.0] * (3 - len(probe))
    time = case.get("time") or {}
    integrator = time.get("integrator") if isinstance(time, dict) else None
    if integrator is not None and not isinstance(integrator, str):
        fail("time.integrator", f"expected a name, got {integrator!r}")
    cracks = case.get("cracks") or []
    if not isinstance(cracks, list) or not all(
            isinstance(c, dict) and all(isinstance(c.get(k), list) and len(c[k]) in (2, 3)
                                        and all(_is_number(v) for v in c[k]) for k in ("from", "to"))
            for c in cracks):
        fail("cracks", f"expected a list of {{from: [x, y, z], to: [x, y, z]}} in m, got {cracks!r}")
    cracks = [([float(v) for v in c["from"]], [float(v) for v in c["to"]]) for c in cracks]
    blocks = case.get("blocks") or []
    block_names = {b["id"]: b["name"] for b in blocks if isinstance(b, dict)
                   and isinstance(b.get("id"), int) and isinstance(b.get("name"), str)}
    return CaseSettings(name=name, dimension=dimension, title=title,
                        grid_spacing=None if spacing is None else float(spacing),
                        times=times, component=int(component), dpi=dpi, block_names=block_names, gmsh=gmsh,
                        integrator=integrator, probe=probe, cracks=cracks,
                        breakable=any(isinstance(b, dict) and b.get("fracture_energy") is not None for b in blocks))
