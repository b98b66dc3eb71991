// The LPS kernel's view of a model (materials/lps/lps.hpp): plain pointers into the model, the
// law's per-node constants and u, and the per-bond and per-row quantities every sweep shares — the
// force and breaking sweeps (lps_kernel.cpp) and the tangent's diagonal blocks (lps_tangent.cpp).
#pragma once
#include <cfloat>
#include <cmath>
#include <cstdint>

#include "core/avx2.hpp"
#include "materials/lps/lps.hpp"

namespace pd {

// A stretch with |s| ≤ kStretchZero is set to zero, as PMB does (thesis §2.2, machine-precision
// remark): round-off in y_j − y_i under a rigid motion would otherwise create forces.
constexpr double kLpsStretchZero = 4.0 * DBL_EPSILON;

// Plain pointers into the model, the law's per-node constants and u, so the sweeps are loops over arrays.
struct LpsKernel {
  const std::int64_t* offsets;
  const std::int32_t* neighbour;
  std::uint8_t* broken;  // written only by the breaking sweep, row by row
  VolumeWeight volume_weight;
  const double* factor;  // surface-correction factor g_k per directed bond; null: none (g = 1)
  const double* x[3];
  const double* u[3];
  const double* volume;
  const double* m;      // m_i
  const double* kappa;  // κ_i
  const double* a;      // α_i/m_i
  const double* b;      // dκ_i/m_i
  double d;
  Influence kind;
  double horizon;
  std::int64_t nodes;
  bool avx2;  // the fast sweeps' rows by the AVX2 code (lps_row_avx2.hpp): avx2_rows() (core/avx2.hpp) when made

  LpsKernel(const LpsModel& law, const Model& model, const Vec3Array& uu) {
    offsets = model.bonds.offsets.data();
    neighbour = model.bonds.neighbour.data();
    broken = const_cast<std::uint8_t*>(model.bonds.broken.data());
    volume_weight = model.bonds.volume_weight;
    factor = model.bonds.corrected() ? model.bonds.surface_factor.data() : nullptr;
    for (int q = 0; q < 3; ++q) {
      x[q] = model.nodes.x[static_cast<std::size_t>(q)].data();
      u[q] = uu[static_cast<std::size_t>(q)].data();
    }
    volume = model.nodes.volume.data();
    m = law.m_.data();
    kappa = law.kappa_.data();
    a = law.a_.data();
    b = law.b_.data();
    d = law.d_;
    kind = law.influence_;
    horizon = law.horizon_;
    nodes = static_cast<std::int64_t>(model.nodes.size());
    avx2 = avx2_rows();
  }

  // Bond k = i→j at u: |ξ|, e = y_j − y_i, y = |e|, raw = y − |ξ| and the extension ext = raw but
  // 0 where |raw| ≤ kLpsStretchZero·|ξ| (round-off), 1/y (1 for a crushed bond: its
  // direction is e = 0, so it pulls nowhere), ω and the weighted volume V_j ν_j g_q (g_q the
  // surface-correction factor of bond q: a correction weights the bond in every sum of the law
  // but m_i, lps.hpp).
  struct Bond {
    double length, e0, e1, e2, y, raw, ext, inv_y, omega, vj;
    // The breaking criterion (PMB's s > s0, without a division): y − |ξ| > s0 |ξ|. Both copies of
    // a bond see bitwise the same y and |ξ|, so they break in the same sweep.
    bool over(double s0) const { return raw > s0 * length; }
  };
  Bond bond(std::int64_t i, std::int64_t q) const {
    const std::int64_t j = neighbour[q];
    Bond t;
    const double d0 = x[0][j] - x[0][i], d1 = x[1][j] - x[1][i], d2 = x[2][j] - x[2][i];
    t.length = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);  // core/bonds.hpp bond_length
    t.e0 = (x[0][j] + u[0][j]) - (x[0][i] + u[0][i]);
    t.e1 = (x[1][j] + u[1][j]) - (x[1][i] + u[1][i]);
    t.e2 = (x[2][j] + u[2][j]) - (x[2][i] + u[2][i]);
    t.y = std::sqrt(t.e0 * t.e0 + t.e1 * t.e1 + t.e2 * t.e2);
    const double ext = t.y - t.length;
    const bool real = std::fabs(ext) > kLpsStretchZero * t.length;
    t.raw = ext;
    t.ext = real ? ext : 0.0;
    t.inv_y = 1.0 / (t.y > 0.0 ? t.y : 1.0);
    t.omega = influence(kind, t.length, horizon);
    t.vj = volume[j] * volume_weight(t.length);
    if (factor) t.vj *= factor[q];
    return t;
  }

  // Σ ω|ξ| e V_j and m'_i = Σ ω|ξ|² V_j over row i's intact bonds.
  void row_sums(std::int64_t i, double& sum_theta, double& m_intact) const {
    double st = 0.0, sm = 0.0;
    for (std::int64_t k = offsets[i]; k < offsets[i + 1]; ++k) {
      if (broken[k]) continue;
      const Bond t = bond(i, k);
      st += t.omega * t.length * t.ext * t.vj;
      sm += t.omega * t.length * t.length * t.vj;
    }
    sum_theta = st;
    m_intact = sm;
  }

  double theta_of(std::int64_t i, double sum_theta) const { return m[i] > 0.0 ? d / m[i] * sum_theta : 0.0; }

  // P_i of lps.hpp: t_ij = ω(|ξ| P_i + a_i e).
  double p_of(std::int64_t i, double theta, double m_intact) const {
    return m[i] > 0.0 ? theta * (b[i] - a[i] / d - a[i] * (m[i] - m_intact) / (d * m[i])) : 0.0;
  }

  // W_i = (κ/2)θ² + (a_i/2) Σ ω (e − θ|ξ|/d)² V_j over row i's intact bonds.
  double row_energy(std::int64_t i, double theta) const {
    double dev = 0.0;
    for (std::int64_t k = offsets[i]; k < offsets[i + 1]; ++k) {
      if (broken[k]) continue;
      const Bond t = bond(i, k);
      const double ed = t.ext - theta * t.length / d;
      dev += t.omega * ed * ed * t.vj;
    }
    return 0.5 * kappa[i] * theta * theta + 0.5 * a[i] * dev;
  }
};

}  // namespace pd
