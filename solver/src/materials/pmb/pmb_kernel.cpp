// The PMB bond-force kernel and the bond-level quantities derived from stretches.
#include "materials/pmb/pmb.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/avx2.hpp"
#include "core/exact_sum.hpp"
#include "materials/pmb/pmb_row.hpp"
#include "materials/pmb/pmb_row_avx2.hpp"

namespace pd {

PmbArrays pmb_arrays(const Model& m, const Vec3Array& u) {
  PmbArrays a;
  a.offsets = m.bonds.offsets.data();
  a.neighbour = m.bonds.neighbour.data();
  a.broken = m.bonds.broken.data();
  a.volume_weight = m.bonds.volume_weight;
  for (int d = 0; d < 3; ++d) {
    a.x[d] = m.nodes.x[static_cast<std::size_t>(d)].data();
    a.u[d] = u[static_cast<std::size_t>(d)].data();
  }
  a.volume = m.nodes.volume.data();
  a.block = m.block_index.data();
  a.c_pair = m.material.micromodulus_pair.data();
  a.factor = m.bonds.corrected() ? m.bonds.surface_factor.data() : nullptr;
  a.blocks = m.material.blocks;
  a.nodes = static_cast<std::int64_t>(m.nodes.size());
  // A lattice of full volumes (the benchmark bricks, most cases): one pass over the nodes, against
  // 122 bonds per node in the kernel.
  a.uniform = a.blocks == 1 && !a.factor && a.volume_weight.outer == HUGE_VAL && a.nodes > 0;
  for (std::int64_t i = 1; a.uniform && i < a.nodes; ++i) a.uniform = a.volume[i] == a.volume[0];
  a.avx2 = avx2_rows();
  return a;
}

namespace {

// The breaking criterion, in one place (every pass that breaks or asks whether a bond would break
// calls these two): bond i→j is compared with s0 of its block pair, or by LAMMPS's α rule with
// min(s0_i, s0_j) of the previous pass (s0_node not null, docs/theory.md T4); it breaks when intact,
// over that threshold and with no end in a no-fail set.
inline double critical_stretch_of(const double* s0_row, std::int32_t bj, const double* s0_node, std::int64_t i,
                                  std::int64_t j) {
  return s0_node ? std::min(s0_node[i], s0_node[j]) : s0_row[bj];
}
inline bool bond_breaks(bool intact, double s, double s0, bool no_fail_end) {
  return over_critical(intact, s, s0) && !no_fail_end;
}

// The energy a bond takes with it when it breaks: ½ c s0² |ξ| ν V_i V_j, the two ¼-shares that W_i
// and W_j held (docs/theory.md C4), at the critical stretch s0 it crossed, not at the stretch s > s0
// it has after the step that broke it. A bond passes s0 somewhere inside that step; its post-step
// stretch, which grows with the strain rate × Δt, counted energy the bond never stored (issue 16:
// on the impact case the energy sum ended 4.5 % above the input).
inline double broken_bond_energy(double c, double s0, double length, double nu, double vi, double vj) {
  return 0.5 * c * s0 * s0 * length * nu * vi * vj;
}

// The breaking criterion, in one place: a bond over its critical stretch breaks unless an end is in a
// no-fail set. Breaks such bonds of row i: sets their flags (only row i's, so no other thread writes
// them), sets br.lost[i], adds the number of bonds i < j broken now to once and returns the number
// of row i's flags it set.
std::int64_t break_row(const PmbArrays& a, const PmbBreaking& br, std::int64_t i, std::int64_t& once) {
  const double* c_row = a.c_pair + a.block[i] * a.blocks;
  const double* s0_row = br.s0_pair + a.block[i] * a.blocks;
  const double xi[3] = {a.x[0][i], a.x[1][i], a.x[2][i]};
  const double yi[3] = {xi[0] + a.u[0][i], xi[1] + a.u[1][i], xi[2] + a.u[2][i]};
  std::int64_t set = 0;
  double lost = 0.0;
  const std::int64_t end = br.no_fail[i] ? a.offsets[i] : a.offsets[i + 1];  // a no-fail node: nothing
  for (std::int64_t k = a.offsets[i]; k < end; ++k) {
    const std::int64_t j = a.neighbour[k];
    const BondTerms b = bond_terms(a, xi, yi, j);
    const double s0 = critical_stretch_of(s0_row, a.block[j], nullptr, i, j);
    if (!bond_breaks(a.broken[k] == 0, b.s, s0, br.no_fail[j] != 0)) continue;
    br.broken[k] = 1;
    ++set;
    if (i < j) {
      ++once;
      double e = broken_bond_energy(c_row[a.block[j]], s0, b.length, a.volume_weight(b.length), a.volume[i], a.volume[j]);
      if (a.factor) e *= a.factor[k];  // the surface correction scales c of this bond
      lost += e;
    }
  }
  if (br.lost) br.lost[i] = lost;
  return set;
}

// Row i with the given switches: the AVX2 code where pmb_arrays chose it, else the portable code;
// the same bits either way.
template <bool kBreaking, bool kOneBlock, bool kCorrected = false, bool kUniform = false>
RowSums pmb_row(const PmbArrays& a, std::int64_t i, const double* s0_pair) {
#ifdef PD_HAVE_AVX2_ROWS
  if (a.avx2) return pmb_row_avx2<kBreaking, kOneBlock, kCorrected, kUniform>(a, i, s0_pair);
#endif
  return pmb_row_part<kBreaking, kOneBlock, kCorrected, kUniform>(a, i, s0_pair, a.offsets[i], RowSums{});
}

// pmb_row with the switches of this row and model.
template <bool kBreaking>
RowSums pmb_row_of(const PmbArrays& a, std::int64_t i, const double* s0_pair) {
  if (a.uniform) return pmb_row<kBreaking, true, false, true>(a, i, s0_pair);
  if (a.factor) return a.blocks == 1 ? pmb_row<kBreaking, true, true>(a, i, s0_pair) : pmb_row<kBreaking, false, true>(a, i, s0_pair);
  return a.blocks == 1 ? pmb_row<kBreaking, true>(a, i, s0_pair) : pmb_row<kBreaking, false>(a, i, s0_pair);
}

}  // namespace

std::int64_t add_pmb_force_density(const PmbArrays& a, double* f0, double* f1, double* f2, double* w,
                                   const PmbBreaking* breaking, RowSubset rows) {
  std::int64_t newly = 0;  // integer sum: exact, so the reduction order does not matter
  const double* s0_pair = breaking ? breaking->s0_pair : nullptr;
  const std::int64_t count = rows.size(a.nodes);
#pragma omp parallel for schedule(static) reduction(+ : newly)
  for (std::int64_t r_at = 0; r_at < count; ++r_at) {
    const std::int64_t i = rows.at(r_at);
    const bool test_breaking = breaking != nullptr && breaking->no_fail[i] == 0;
    RowSums r = test_breaking ? pmb_row_of<true>(a, i, s0_pair) : pmb_row_of<false>(a, i, s0_pair);
    if (r.over > 0) {  // rare: near a crack tip or a no-fail set
      // A bond that breaks now adds no force (it breaks before the force at this state, thesis
      // §2.2 order): the row again, from the new flags, so the result is bitwise that of
      // update_broken_bonds followed by the force.
      if (break_row(a, *breaking, i, newly) > 0)
        r = a.factor ? pmb_row<false, false, true>(a, i, s0_pair) : pmb_row<false, false>(a, i, s0_pair);
    } else if (breaking && breaking->lost) {
      breaking->lost[i] = 0.0;
    }
    f0[i] += r.f0;
    f1[i] += r.f1;
    f2[i] += r.f2;
    if (w) w[i] = r.w;
  }
  return newly;
}

void add_pmb_force(const Model& model, const Vec3Array& u, Vec3Array& f, double* energy_density, RowSubset rows) {
  add_pmb_force_density(pmb_arrays(model, u), f[0].data(), f[1].data(), f[2].data(), energy_density, nullptr, rows);
}

namespace {

PmbBreaking pmb_breaking(Model& m, double* lost) {
  return PmbBreaking{m.bonds.broken.data(), m.material.critical_pair.data(), m.no_fail.data(), lost};
}

}  // namespace

std::int64_t update_broken_bonds(Model& m, const Vec3Array& u, double* energy) {
  if (!m.material.can_break()) return 0;  // then no pass looks at breaking at all
  const PmbArrays a = pmb_arrays(m, u);
  // Energy of the bonds broken now, per node i (the i < j copy of each bond), summed serially below.
  std::vector<double> lost(energy ? static_cast<std::size_t>(a.nodes) : 0, 0.0);
  const PmbBreaking br = pmb_breaking(m, energy ? lost.data() : nullptr);
  std::int64_t newly = 0;  // integer sum: exact, so the reduction order does not matter
#pragma omp parallel for schedule(static) reduction(+ : newly)
  for (std::int64_t i = 0; i < a.nodes; ++i) break_row(a, br, i, newly);
  if (energy && newly > 0)
    *energy += exact_sum(lost);  // exact (core/exact_sum.hpp): the decomposed run's bits too
  return newly;
}

std::int64_t break_bonds_and_add_pmb_force(Model& m, const Vec3Array& u, Vec3Array& f, double* energy_density,
                                           double* broken_energy, double* lost_per_node, RowSubset rows) {
  const PmbArrays a = pmb_arrays(m, u);
  if (!m.material.can_break()) {
    add_pmb_force_density(a, f[0].data(), f[1].data(), f[2].data(), energy_density, nullptr, rows);
    return 0;
  }
  if (lost_per_node) {
    const PmbBreaking br = pmb_breaking(m, lost_per_node);
    return add_pmb_force_density(a, f[0].data(), f[1].data(), f[2].data(), energy_density, &br, rows);
  }
  std::vector<double> lost(broken_energy ? static_cast<std::size_t>(a.nodes) : 0, 0.0);
  const PmbBreaking br = pmb_breaking(m, broken_energy ? lost.data() : nullptr);
  const std::int64_t newly = add_pmb_force_density(a, f[0].data(), f[1].data(), f[2].data(), energy_density, &br, rows);
  if (broken_energy && newly > 0)
    *broken_energy += exact_sum(lost);  // exact, as update_broken_bonds
  return newly;
}

bool uses_lammps_rules(const Model& m) { return m.break_after_force || node_critical_stretch(m) != nullptr; }

std::int64_t break_bonds_lammps_rules(Model& m, const Vec3Array& u, Vec3Array* f, double* energy_density,
                                      double* broken_energy, double* lost_per_node, const GhostsInFlight* ghosts) {
  const PmbArrays a = pmb_arrays(m, u);
  // Every row at once, or the interior rows while the ghosts travel and then the boundary rows.
  const auto sweep = [&](auto&& pass) { return ghosts ? sweep_overlapped(*ghosts, pass) : pass(RowSubset{}); };
  if (!m.material.can_break()) {  // nothing can break: the force alone, as the thesis path
    if (f)
      sweep([&](RowSubset rows) {
        return add_pmb_force_density(a, (*f)[0].data(), (*f)[1].data(), (*f)[2].data(), energy_density, nullptr, rows);
      });
    else if (ghosts) ghosts->wait();
    return 0;
  }
  const auto n = static_cast<std::size_t>(a.nodes);
  std::vector<double>* s0_now = node_critical_stretch(m);
  const bool node_rule = s0_now != nullptr;
  const bool force_first = m.break_after_force;
  const double* s0_node = node_rule ? s0_now->data() : nullptr;
  // A row not swept (a ghost's, on a decomposed run: its row is empty) keeps +inf, as a row without
  // intact bonds gets in the sweep (LAMMPS's DBL_MAX).
  std::vector<double> s0_next(node_rule ? n : 0, std::numeric_limits<double>::infinity());
  std::vector<double> lost(broken_energy && !lost_per_node ? n : 0, 0.0);
  double* lost_out = lost_per_node ? lost_per_node : (broken_energy ? lost.data() : nullptr);
  std::uint8_t* broken = m.bonds.broken.data();
  const double* s0_pair = m.material.critical_pair.data();
  const double* alpha_pair = m.material.alpha_pair.data();
  const std::uint8_t* no_fail = m.no_fail.data();
  // One pass over `rows`: each row reads the previous pass's s0 of both ends (s0_node, ghosts
  // included) and writes only its own flags, s0_next, lost and force, so the rows may be swept in
  // any order and in two halves (parallel/row_split.hpp): the same bits.
  const auto pass = [&](RowSubset rows) {
    std::int64_t newly = 0;  // integer sum: exact, so the reduction order does not matter
    const std::int64_t count = rows.size(a.nodes);
#pragma omp parallel for schedule(static) reduction(+ : newly)
    for (std::int64_t r_at = 0; r_at < count; ++r_at) {
      const std::int64_t i = rows.at(r_at);
      const auto iu = static_cast<std::size_t>(i);
      RowSums r{0.0, 0.0, 0.0, 0.0, 0};
      // LAMMPS order: the force of every bond intact at the start of the pass, those breaking now too.
      if (f && force_first) r = a.factor ? pmb_row<false, false, true>(a, i, nullptr) : pmb_row<false, false>(a, i, nullptr);
      const double* c_row = a.c_pair + a.block[i] * a.blocks;
      const double* s0_row = s0_pair + a.block[i] * a.blocks;
      const double* alpha_row = alpha_pair + a.block[i] * a.blocks;
      const double xi[3] = {a.x[0][i], a.x[1][i], a.x[2][i]};
      const double yi[3] = {xi[0] + a.u[0][i], xi[1] + a.u[1][i], xi[2] + a.u[2][i]};
      double next = std::numeric_limits<double>::infinity();  // a node without intact bonds: LAMMPS's DBL_MAX
      bool first = true;
      double lost_i = 0.0;
      for (std::int64_t k = a.offsets[i]; k < a.offsets[i + 1]; ++k) {
        if (broken[k]) continue;
        const std::int64_t j = a.neighbour[k];
        const BondTerms b = bond_terms(a, xi, yi, j);
        const std::int32_t bj = a.block[j];
        if (node_rule) {  // s0_i for the next pass, from this pass's stretches (bonds breaking now too)
          const double candidate = s0_row[bj] - alpha_row[bj] * b.s;
          next = first ? candidate : std::max(next, candidate);
          first = false;
        }
        // The previous pass's s0 at both ends: both copies of the bond see the same threshold and
        // bitwise the same stretch, so they break in the same pass.
        const double s0 = critical_stretch_of(s0_row, bj, s0_node, i, j);
        if (!bond_breaks(true, b.s, s0, no_fail[i] || no_fail[j])) continue;
        broken[k] = 1;
        if (i < j) {
          ++newly;
          double e = broken_bond_energy(c_row[bj], s0, b.length, a.volume_weight(b.length), a.volume[i], a.volume[j]);
          if (a.factor) e *= a.factor[k];  // the surface correction scales c of this bond
          lost_i += e;
        }
      }
      if (node_rule) s0_next[iu] = next;
      if (lost_out) lost_out[iu] = lost_i;
      // Thesis order: the force from the flags after breaking (a bond over s0 adds no force).
      if (f && !force_first) r = a.factor ? pmb_row<false, false, true>(a, i, nullptr) : pmb_row<false, false>(a, i, nullptr);
      if (f) {
        (*f)[0][iu] += r.f0;
        (*f)[1][iu] += r.f1;
        (*f)[2][iu] += r.f2;
        if (energy_density) energy_density[iu] = r.w;
      }
    }
    return newly;
  };
  const std::int64_t newly = sweep(pass);
  if (node_rule) s0_now->swap(s0_next);  // every row read the previous s0 above
  if (broken_energy && !lost_per_node && newly > 0)
    *broken_energy += exact_sum(lost);  // exact, as update_broken_bonds
  return newly;
}

StretchRatio pmb_stretch_ratio(const Model& m, const Vec3Array& u) {
  StretchRatio out;
  if (!m.material.can_break()) return out;  // no threshold anywhere: nothing can break
  const PmbArrays a = pmb_arrays(m, u);
  // The thresholds break_bonds compares with: LAMMPS's per-node s0 of the previous pass when its α
  // rule is on (break_bonds_lammps_rules), else the pair table's (break_row).
  const std::vector<double>* s0_now = node_critical_stretch(m);
  const double* s0_node = s0_now ? s0_now->data() : nullptr;
  const double* s0_pair = m.material.critical_pair.data();
  const std::uint8_t* no_fail = m.no_fail.data();
  double largest = 0.0;
  std::int64_t over = 0;  // a maximum and an integer sum: exact in any order of rows and threads
#pragma omp parallel for schedule(static) reduction(max : largest) reduction(+ : over)
  for (std::int64_t i = 0; i < a.nodes; ++i) {
    if (no_fail[i]) continue;  // a no-fail node's bonds never break, whatever their stretch
    const double* s0_row = s0_pair + a.block[i] * a.blocks;
    const double xi[3] = {a.x[0][i], a.x[1][i], a.x[2][i]};
    const double yi[3] = {xi[0] + a.u[0][i], xi[1] + a.u[1][i], xi[2] + a.u[2][i]};
    for (std::int64_t k = a.offsets[i]; k < a.offsets[i + 1]; ++k) {
      const std::int64_t j = a.neighbour[k];
      if (a.broken[k] || no_fail[j]) continue;
      const BondTerms b = bond_terms(a, xi, yi, j);  // the stretch every pass computes, bit for bit
      const double s0 = critical_stretch_of(s0_row, a.block[j], s0_node, i, j);
      if (s0 > 0.0 && s0 < std::numeric_limits<double>::infinity()) largest = std::max(largest, b.s / s0);
      if (i < j && bond_breaks(true, b.s, s0, false)) ++over;  // each bond once, as BreakReport counts
    }
  }
  out.largest = largest;
  out.over = over;
  return out;
}

std::vector<double> strain_energy_density(const Model& m, const Vec3Array& u) {
  const PmbArrays a = pmb_arrays(m, u);
  std::vector<double> w(static_cast<std::size_t>(a.nodes), 0.0);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < a.nodes; ++i) {
    const double* c_row = a.c_pair + a.block[i] * a.blocks;
    const double xi[3] = {a.x[0][i], a.x[1][i], a.x[2][i]};
    const double yi[3] = {xi[0] + a.u[0][i], xi[1] + a.u[1][i], xi[2] + a.u[2][i]};
    double sum = 0.0;
    for (std::int64_t k = a.offsets[i]; k < a.offsets[i + 1]; ++k) {
      if (a.broken[k]) continue;
      const std::int64_t j = a.neighbour[k];
      const BondTerms b = bond_terms(a, xi, yi, j);
      // ¼ c s² |ξ| V_j: each bond is visited from both ends, so each end takes half of the
      // bond's ½ c s² |ξ| V_i V_j (docs/theory.md C4).
      double e = 0.25 * c_row[a.block[j]] * b.s * b.s * b.length * a.volume[j] * a.volume_weight(b.length);
      if (a.factor) e *= a.factor[k];
      sum += e;
    }
    w[static_cast<std::size_t>(i)] = sum;
  }
  return w;
}

double strain_energy(const Model& m, const Vec3Array& u) {
  const std::vector<double> w = strain_energy_density(m, u);
  double total = 0.0;
  for (std::size_t i = 0; i < w.size(); ++i) total += w[i] * m.nodes.volume[i];
  return total;
}

}  // namespace pd
