"""peridyn: drive the toolchain from Python: load a case, change keys, run it through the same
stages as `make` (mesh → preprocess → solve → postprocess), and read its history and frames as numpy
arrays. For parameter studies (docs/python-api.md):

    import peridyn
    case = peridyn.load("cases/branching/branching.yaml")
    case["materials.glass.fracture_energy"] = 5.0         # any key of docs/case-file.md, dotted
    run = case.run("out/study/G5")                         # raises CaseError / RunError on failure
    run.history["kinetic_energy"]                          # numpy arrays, one per history.csv column
    frame = run.frame(-1); frame.damage, frame.displacement, frame.points

A run's folder holds what `make` writes (case.json, nodes.vtu, history.csv, frames/, figures/ …)
plus the case file it was run from, <out>/<name>.yaml. peridyn.open(out_dir) reads a finished run.
"""
from .case import Case, RunError, load
from .results import Run, open_run as open

__all__ = ["Case", "Run", "RunError", "load", "open"]
