"""Static tension (docs/theory.md C3): a 100 × 40 mm plane-stress plate held in x along its left end
row and pulled by σ = 1 MPa (a body force σ/dx on its right end row), brought to equilibrium by
velocity damping (dynamic relaxation). The interior strains are fitted over the middle of the plate,
2δ away from every edge: ε_xx against σ/E and ε_yy against −ν·σ/E (plane-stress PMB: ν = 1/3),
within the C1 lattice factor, with and without partial volumes (discretization.partial_volume).

Expected discrete values: for a homogeneous strain the PMB stress is σ_ab = C_abcd ε_cd with
C_abcd = ½·c·Σ_j ν_j V_j ξ_a ξ_b ξ_c ξ_d / |ξ|³ (the lattice sum over a bulk node's family; its
continuum limit is the plane-stress tensor of E, ν = 1/3), so uniaxial stress σ gives
ε_xx = σ·C22/(C11·C22 − C12²), ε_yy = −(C12/C22)·ε_xx."""
from __future__ import annotations

import os

import numpy as np

from .common import Check, Run
from .runner import ROOT, run_case

MODELS = os.path.join(ROOT, "validation", "models")
SIGMA = 1.0e6
NU = 1.0 / 3.0
LATTICE_TOLERANCE = 0.02   # measured vs the lattice-sum prediction: the plate's free edges (softer
                           # surface layers, H = 13δ) leave the interior 1.3 % more strained (measured)
FINITE_PLATE = 0.02        # added to the lattice-sum deviation for the continuum comparison


def lattice_tensor(dx: float, delta: float, h: float, E: float, partial_volume: str) -> tuple[float, float, float]:
    """(C11, C22, C12) [Pa] of the square lattice with the solver's volume weights (docs/theory.md T5)."""
    n = int(np.ceil(delta / dx)) + 2
    i, j = np.meshgrid(np.arange(-n, n + 1), np.arange(-n, n + 1), indexing="ij")
    x, y = i.ravel() * dx, j.ravel() * dx
    r = np.hypot(x, y)
    keep = r > 0
    x, y, r = x[keep], y[keep], r[keep]
    if partial_volume == "none":
        w = (r <= delta * (1 + 1e-12)).astype(float)
    elif partial_volume == "lammps":
        w = np.where(r <= delta - dx / 2, 1.0, np.where(r <= delta, (delta - r) / dx + 0.5, 0.0))
    elif partial_volume == "hhb":
        w = np.where(r <= delta - dx / 2, 1.0, np.where(r - dx / 2 <= delta, (delta - r + dx / 2) / dx, 0.0))
    else:
        raise ValueError(partial_volume)
    c = 9.0 * E / (np.pi * h * delta ** 3)
    V = dx * dx * h
    s = 0.5 * c * V * w / r ** 3
    return float(np.sum(s * x ** 4)), float(np.sum(s * y ** 4)), float(np.sum(s * x * x * y * y))


def predicted_strains(run: Run) -> tuple[float, float]:
    block = run.case["blocks"][0]
    c11, c22, c12 = lattice_tensor(run.dx, run.horizon, run.case["thickness"], block["youngs_modulus"],
                                   run.case["partial_volume"])
    exx = SIGMA * c22 / (c11 * c22 - c12 ** 2)
    return exx, -c12 / c22 * exx


def interior_strains(run: Run) -> tuple[float, float]:
    """(ε_xx, ε_yy): least-squares planes u = a + b·x + c·y over the nodes 2δ or more from every edge
    and in the middle 60 % of the length, in the last frame."""
    x = run.x
    lo, hi = x.min(axis=0), x.max(axis=0)
    margin = 2 * run.horizon
    length = hi[0] - lo[0]
    sel = ((x[:, 0] > lo[0] + 0.2 * length) & (x[:, 0] < hi[0] - 0.2 * length)
           & (x[:, 1] > lo[1] + margin) & (x[:, 1] < hi[1] - margin))
    u = run.frame(-1).displacement
    A = np.column_stack([np.ones(sel.sum()), x[sel, 0], x[sel, 1]])
    bx = np.linalg.lstsq(A, u[sel, 0], rcond=None)[0]
    by = np.linalg.lstsq(A, u[sel, 1], rcond=None)[0]
    return float(bx[1]), float(by[2])


def changes(dx: float = 1.0e-3, horizon_factor: float = 3.015, partial_volume: str = "none") -> dict:
    return {"discretization": {"dx": dx, "horizon_factor": horizon_factor, "partial_volume": partial_volume},
            "boundary_conditions": [{"set": "left", "displacement": {"x": 0.0}},
                                    {"set": "right", "body_force": {"x": SIGMA / dx}}]}


def run_one(work: str, **kw) -> dict:
    out, seconds = run_case("static", work, changes(**kw), figures=False, source=MODELS)
    run = Run(out)
    exx, eyy = interior_strains(run)
    pxx, pyy = predicted_strains(run)
    h = run.history
    rest = float(h["kinetic_energy"][-1] / max(h["strain_energy"][-1], 1e-300))
    E = run.case["blocks"][0]["youngs_modulus"]
    return dict(kw, out=out, seconds=seconds, exx=exx, eyy=eyy, pxx=pxx, pyy=pyy, rest=rest,
                exx0=SIGMA / E, eyy0=-NU * SIGMA / E, m=run.horizon / run.dx, delta=run.horizon)


MAIN = ("none", "hhb", "lammps")
SWEEP_M = (2.015, 3.015, 4.015, 5.015)             # at dx = 1 mm
SWEEP_DX = (2.0e-3, 1.5e-3, 1.0e-3)                 # at m = 3.015


def run_all(work: str) -> dict:
    result = {"main": [], "m": [], "dx": []}
    for pv in MAIN:
        result["main"].append(run_one(os.path.join(work, f"pv_{pv}"), partial_volume=pv))
    for factor in SWEEP_M:
        if factor == 3.015:
            result["m"].append(result["main"][0])
            continue
        result["m"].append(run_one(os.path.join(work, f"m{factor:g}"), horizon_factor=factor))
    for dx in SWEEP_DX:
        if dx == 1.0e-3:
            result["dx"].append(result["main"][0])
            continue
        result["dx"].append(run_one(os.path.join(work, f"dx{dx * 1e3:g}mm"), dx=dx))
    return result


def lattice_factor(pv: str, factor: float = 3.015) -> float:
    """C1's R_W for the 2D square lattice (ΣV_jν_j|ξ_j| over its continuum value)."""
    c11, c22, c12 = lattice_tensor(1.0, factor, 1.0, 1.0, pv)
    return (c11 + c12) / (9.0 / 8.0 + 3.0 / 8.0)


def checks_from(result: dict, case: str = "static") -> list[Check]:
    rows = []
    for r in result["main"]:
        pv = r["partial_volume"]
        for name, got, cont, pred in (("ε_xx", r["exx"], r["exx0"], r["pxx"]), ("ε_yy", r["eyy"], r["eyy0"], r["pyy"])):
            # the lattice tensor's own deviation (for ε_xx about C1's factor R_W = lattice_factor;
            # ε_yy also carries the square lattice's anisotropy: C12/C22 ≠ 1/3) plus 2 %
            tol = abs(pred / cont - 1.0) + FINITE_PLATE
            rows.append(Check(case, f"interior {name} / continuum ({'σ/E' if name == 'ε_xx' else '−νσ/E'}), "
                                    f"partial_volume {pv}, m = 3",
                              f"1 ± {tol:.3f} (lattice sum {pred / cont:.4f}, R_W {lattice_factor(pv):.4f}; + 2 %)",
                              got / cont,
                              bool(abs(got / cont - 1.0) <= tol),
                              note=f"lattice-sum prediction {pred / cont:.4f}; measured/predicted "
                                   f"{got / pred:.4f}; KE/U at the end {r['rest']:.1e}"))
            rows.append(Check(case, f"interior {name} / lattice-sum prediction, partial_volume {pv}",
                              f"1 ± {LATTICE_TOLERANCE:g}", got / pred, bool(abs(got / pred - 1.0) <= LATTICE_TOLERANCE)))
    return rows


def figure(result: dict, path: str):
    from postprocess.plotting import new_figure, save_figure
    r = result["main"][0]
    run = Run(r["out"])
    x, u = run.x, run.frame(-1).displacement
    mid = np.abs(x[:, 1] - np.median(x[:, 1])) < 0.51 * run.dx
    col = np.abs(x[:, 0] - np.median(x[:, 0])) < 0.51 * run.dx
    fig, axes = new_figure(1, 2, size=(11.0, 4.5))
    ax = axes[0, 0]
    ax.plot(x[mid, 0] * 1e3, u[mid, 0] * 1e6, ".", ms=3, label="u_x, middle row (partial_volume none)")
    xs = np.array([x[:, 0].min(), x[:, 0].max()])
    ax.plot(xs * 1e3, r["exx0"] * (xs - xs[0]) * 1e6, "k--", lw=1, label="σ/E · x")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("u_x [µm]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax.set_title("static tension: σ = 1 MPa, E = 1 GPa")
    ax = axes[0, 1]
    ys = x[col, 1]
    ax.plot(ys * 1e3, (u[col, 1] - np.mean(u[col, 1])) * 1e6, ".", ms=3, label="u_y, middle column")
    ax.plot(ys * 1e3, r["eyy0"] * (ys - ys.mean()) * 1e6, "k--", lw=1, label="−νσ/E · (y − y_c)")
    ax.set_xlabel("y [mm]")
    ax.set_ylabel("u_y [µm]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax.set_title(", ".join(f"{m['partial_volume']}: ε_xx/(σ/E) = {m['exx'] / m['exx0']:.3f}" for m in result["main"]),
                 fontsize=8)
    save_figure(fig, path)


def validate(report_dir: str) -> list[Check]:
    result = run_all(os.path.join(report_dir, "work", "static"))
    figure(result, os.path.join(report_dir, "static.png"))
    validate.result = result
    return checks_from(result)
