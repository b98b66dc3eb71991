"""The energy surface correction (Le & Bobaru 2018) as solver/src/core/surface_correction.cpp computes
it, for the pre-processor's stable time step (stability.py): with `surface_correction: energy` the
solver multiplies each bond's term of thesis eq. 2.5 by its factor g, so the step checked here must
too (tests/pipeline/test_surface_correction_dt.py holds it equal to `pdsolve --stable-dt`).

The solver probes each node with the uniaxial stress of its material along each axis and compares
the law's energy with the continuum's; here the same with the stretch linearised (s = n·ε·n), which
the solver's mean of +ε and −ε matches to O(ε²) = 1e-10 relative.
"""
from __future__ import annotations

import math

import numpy as np

# The solver's kSurfacePasses: refinement passes after the first.
PASSES = 3


def continuum_energy(law: dict, block: int, strain: np.ndarray, dims: int, horizon: float,
                     thickness: float | None) -> float:
    """BondModel::continuum_energy_density of a block (0-based) for a diagonal strain (3 values):
    PMB (cπδ⁴/60)((tr ε)² + 2ε:ε) (3D), (chπδ³/48)(…) (2D); LPS (κ/2)(tr ε)² + μ ε^d:ε^d."""
    e = strain[:dims]
    tr, contraction = float(np.sum(e)), float(np.sum(e * e))
    if law["model"] == "pmb":
        c = law["c"][block]
        scale = math.pi * horizon ** 4 / 60.0 if dims == 3 else thickness * math.pi * horizon ** 3 / 48.0
        return c * scale * (tr * tr + 2.0 * contraction)
    kappa, mu = law["moduli"][block]
    return 0.5 * kappa * tr * tr + mu * (contraction - tr * tr / dims)


def probe_strain(law: dict, block: int, d: int, dims: int, horizon: float, thickness: float | None) -> np.ndarray:
    """surface_probe_strain: ε = 1 along axis d and −r on the other axes of the analysis, r = B/C from
    the continuum energy W(a, b) = ½A a² + B a b + ½C b² (zero lateral stress)."""
    axial = np.zeros(3)
    axial[d] = 1.0
    lateral = np.zeros(3)
    lateral[[e for e in range(dims) if e != d]] = 1.0
    def w(strain):
        return continuum_energy(law, block, strain, dims, horizon, thickness)
    ratio = (w(axial + lateral) - w(axial) - w(lateral)) / (2.0 * w(lateral))
    return axial - ratio * lateral


def bond_factors(factors: np.ndarray, i: np.ndarray, j: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """bond_surface_factor: s_d = (f_d,i + f_d,j)/2, g = [Σ n_d²/s_d²]^(−½) (the ellipsoid rule)."""
    s = 0.5 * (factors[i] + factors[j])
    return 1.0 / np.sqrt(np.sum(direction * direction / (s * s), axis=1))


def direction_factors(law: dict, n: int, dims: int, horizon: float, thickness: float | None, block: np.ndarray,
                      i: np.ndarray, j: np.ndarray, dist: np.ndarray, direction: np.ndarray, weight: np.ndarray,
                      intact: np.ndarray) -> np.ndarray:
    """surface_direction_factors (n × 3): bonds i→j (every directed bond within the cutoff) of
    length dist and unit direction, weight = V_j ν_j, intact = not across a pre-crack; block 0-based.
    law: {"model": "pmb", "c": c per block, "c_pair": matrix} or {"model": "lps", "moduli": (κ, μ)
    per block, "influence": ω per bond}."""
    blocks = int(block.max()) + 1 if n else 0
    probes = [[probe_strain(law, b, d, dims, horizon, thickness) for d in range(dims)] for b in range(blocks)]
    continuum = np.array([[continuum_energy(law, b, probes[b][d], dims, horizon, thickness)
                           for d in range(dims)] for b in range(blocks)])
    live = weight * intact
    factors = np.ones((n, 3))
    for step in range(PASSES + 1):
        g = np.ones(len(i)) if step == 0 else bond_factors(factors, i, j, direction)
        for d in range(dims):
            probe = np.array([probes[b][d] for b in range(blocks)])[block[i]]  # row i's probe per bond
            stretch = np.sum(probe * direction * direction, axis=1)           # n·ε·n, ε = 1
            if law["model"] == "pmb":
                c = law["c_pair"][block[i], block[j]]
                w = np.bincount(i, weights=0.25 * c * g * live * stretch * stretch * dist, minlength=n)
            else:
                wg = law["influence"] * live * g
                m = np.bincount(i, weights=wg * dist * dist, minlength=n)
                m0 = np.bincount(i, weights=law["influence"] * live * dist * dist, minlength=n)
                gbar = np.divide(m, m0, out=np.ones(n), where=m0 > 0)
                kappa = np.array([k for k, _ in law["moduli"]])[block] * gbar
                alpha = np.array([(15.0 if dims == 3 else 8.0) * mu for _, mu in law["moduli"]])[block] * gbar
                ext = dist * stretch
                theta = dims * np.divide(np.bincount(i, weights=wg * dist * ext, minlength=n), m,
                                         out=np.zeros(n), where=m > 0)
                ed = ext - theta[i] * dist / dims
                dev = np.bincount(i, weights=wg * ed * ed, minlength=n)
                w = 0.5 * kappa * theta * theta + 0.5 * np.divide(alpha, m, out=np.zeros(n), where=m > 0) * dev
            ok = w > 0
            factors[ok, d] *= continuum[block[ok], d] / w[ok]
    return factors
