// The LPS kernel in two sweeps over the bonds (materials/lps/lps.hpp): the first computes every
// node's dilatation θ_i (breaking bonds first where asked), the second the force from θ of both
// ends. Each sweep is parallel over nodes and a node writes only its own row and its own θ, f, W,
// summing its bonds in row order: bitwise the same for any thread count. The sweeps' fast rows are in
// lps_row.hpp (portable) and lps_row_avx2.hpp (AVX2 intrinsics, taken where the CPU has AVX2: the
// same bits, fewer stores; docs/performance.md §2).
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/exact_sum.hpp"
#include "materials/lps/lps_kernel.hpp"
#include "materials/lps/lps_row.hpp"
#include "materials/lps/lps_row_avx2.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

namespace {

// The fast rows of the two sweeps: the AVX2 code where the kernel chose it (LpsKernel::avx2), else
// the portable code (lps_row.hpp); the same bits either way. Every sweep that uses a fast row goes
// through these two: dilatation_sweep_of and force_sweep_of, which the plain, the breaking and the
// overlapped (decomposed) paths and dilatation() all call. The other row loops (the exact redo of
// a row that breaks, dilatation_row; stretch_ratio; strain_energy_density; J·x's two sweeps; the
// tangent's blocks) are per-bond code on LpsKernel::bond, not these rows.
template <Influence kKind, bool kBreaking, bool kOneBlock>
DilatationSums dilatation_row_fast(const LpsKernel& k, std::int64_t i, const double* s0_row, const std::int32_t* block) {
#ifdef PD_HAVE_AVX2_ROWS
  if (k.avx2) return dilatation_row_avx2<kKind, kBreaking, kOneBlock>(k, i, s0_row, block);
#endif
  return dilatation_row_part<kKind, kBreaking, kOneBlock>(k, i, s0_row, block, k.offsets[i], DilatationSums{});
}

template <Influence kKind>
ForceRow force_row_fast(const LpsKernel& k, std::int64_t i, const double* theta, const double* p) {
#ifdef PD_HAVE_AVX2_ROWS
  if (k.avx2) return force_row_avx2<kKind>(k, i, theta, p);
#endif
  return force_row_part<kKind>(k, i, theta, p, k.offsets[i], ForceSums{});
}

// What the breaking sweep needs besides the kernel (the PMB criterion: a bond breaks once its
// stretch exceeds s0 of its block pair, unless an end is in a no-fail set).
struct Breaking {
  const double* s0_pair;
  const std::int32_t* block;
  std::int64_t blocks;
  const std::uint8_t* no_fail;
  double* lost;  // per node, or null: V_i (W_i before − W_i after) [J]
};

// Sweep 1 for row i: θ_i and m'_i; with breaking, first breaks the row's bonds over their critical
// stretch (only row i's flags: both copies of a bond see bitwise the same stretch, since y_j − y_i
// is the exact negative of y_i − y_j, and break in the same sweep). Returns the bonds i < j broken.
std::int64_t dilatation_row(const LpsKernel& k, std::int64_t i, const Breaking* br, double& theta, double& m_intact) {
  double sum_theta = 0.0;
  k.row_sums(i, sum_theta, m_intact);
  theta = k.theta_of(i, sum_theta);
  if (!br || br->no_fail[i]) {
    if (br && br->lost) br->lost[i] = 0.0;
    return 0;
  }
  const double* s0_row = br->s0_pair + br->block[i] * br->blocks;
  std::int64_t over = 0;
  for (std::int64_t q = k.offsets[i]; q < k.offsets[i + 1]; ++q) {
    const std::int64_t j = k.neighbour[q];
    if (k.broken[q] || br->no_fail[j]) continue;
    over += k.bond(i, q).over(s0_row[br->block[j]]);
  }
  if (over == 0) {
    if (br->lost) br->lost[i] = 0.0;
    return 0;
  }
  const double before = br->lost ? k.row_energy(i, theta) : 0.0;
  std::int64_t once = 0;
  for (std::int64_t q = k.offsets[i]; q < k.offsets[i + 1]; ++q) {
    const std::int64_t j = k.neighbour[q];
    if (k.broken[q] || br->no_fail[j] || !k.bond(i, q).over(s0_row[br->block[j]])) continue;
    k.broken[q] = 1;
    once += i < j;
  }
  k.row_sums(i, sum_theta, m_intact);
  theta = k.theta_of(i, sum_theta);
  if (br->lost) br->lost[i] = k.volume[i] * (before - k.row_energy(i, theta));
  return once;
}

// Sweep 1 over every node: θ and P per node. Returns the bonds broken now (each once). A row with
// candidates for breaking (rare: near a crack tip) is redone by dilatation_row, exactly.
// rows: the rows swept (every row by default); theta and p are sized to the nodes (zeros) first
// if they are not, and only the rows' entries are set. A row's θ and P do not depend on which other
// rows are swept (parallel/row_split.hpp).
template <Influence kKind>
std::int64_t dilatation_sweep_of(const LpsKernel& k, const Breaking* br, std::vector<double>& theta,
                                 std::vector<double>& p, RowSubset rows) {
  if (theta.size() != static_cast<std::size_t>(k.nodes)) theta.assign(static_cast<std::size_t>(k.nodes), 0.0);
  if (p.size() != static_cast<std::size_t>(k.nodes)) p.assign(static_cast<std::size_t>(k.nodes), 0.0);
  std::int64_t newly = 0;  // integer sum: exact, so the reduction order does not matter
  const std::int64_t count = rows.size(k.nodes);
#pragma omp parallel for schedule(static) reduction(+ : newly)
  for (std::int64_t r = 0; r < count; ++r) {
    const std::int64_t i = rows.at(r);
    double th = 0.0;
    DilatationSums s;
    if (br && !br->no_fail[i]) {
      const double* s0_row = br->s0_pair + br->block[i] * br->blocks;
      if (br->blocks == 1) s = dilatation_row_fast<kKind, true, true>(k, i, s0_row, br->block);
      else s = dilatation_row_fast<kKind, true, false>(k, i, s0_row, br->block);
    } else {
      s = dilatation_row_fast<kKind, false, true>(k, i, nullptr, nullptr);
    }
    double mi = s.m;
    if (s.over > 0) {
      newly += dilatation_row(k, i, br, th, mi);
    } else {
      th = k.theta_of(i, s.theta);
      if (br && br->lost) br->lost[i] = 0.0;
    }
    theta[static_cast<std::size_t>(i)] = th;
    p[static_cast<std::size_t>(i)] = k.p_of(i, th, mi);
  }
  return newly;
}

std::int64_t dilatation_sweep(const LpsKernel& k, const Breaking* br, std::vector<double>& theta,
                              std::vector<double>& p, RowSubset rows = {}) {
  switch (k.kind) {
    case Influence::inverse_length: return dilatation_sweep_of<Influence::inverse_length>(k, br, theta, p, rows);
    case Influence::gaussian: return dilatation_sweep_of<Influence::gaussian>(k, br, theta, p, rows);
    case Influence::one: break;
  }
  return dilatation_sweep_of<Influence::one>(k, br, theta, p, rows);
}

// Sweep 2: f_i += Σ_j (t_ij + t_ji) V_j e/y, t_ij + t_ji = ω(|ξ|(P_i + P_j) + (a_i + a_j) ext); W_i.
// rows: the rows swept (every row by default), as dilatation_sweep_of.
template <Influence kKind>
void force_sweep_of(const LpsKernel& k, const std::vector<double>& theta, const std::vector<double>& p, Vec3Array& f,
                    double* w, RowSubset rows) {
  const std::int64_t count = rows.size(k.nodes);
#pragma omp parallel for schedule(static)
  for (std::int64_t r_at = 0; r_at < count; ++r_at) {  // not r: the row's sums below are
    const std::int64_t i = rows.at(r_at);
    const ForceRow r = force_row_fast<kKind>(k, i, theta.data(), p.data());
    const auto iu = static_cast<std::size_t>(i);
    f[0][iu] += r.f0;
    f[1][iu] += r.f1;
    f[2][iu] += r.f2;
    if (w) w[i] = r.w;
  }
}

void force_sweep(const LpsKernel& k, const std::vector<double>& theta, const std::vector<double>& p, Vec3Array& f,
                 double* w, RowSubset rows = {}) {
  switch (k.kind) {
    case Influence::inverse_length: return force_sweep_of<Influence::inverse_length>(k, theta, p, f, w, rows);
    case Influence::gaussian: return force_sweep_of<Influence::gaussian>(k, theta, p, f, w, rows);
    case Influence::one: break;
  }
  force_sweep_of<Influence::one>(k, theta, p, f, w, rows);
}

// Both sweeps on a decomposed run, each overlapped with the exchange it needs (parallel/row_split.hpp):
// sweep 1 over the interior rows while u's ghosts travel, then over the boundary rows; P's
// exchange begins once every owned P is known, and sweep 2 goes over the interior rows (P_j of
// owned nodes only) while it travels, then over the boundary rows. The same θ, P, flags, f and W
// as the plain sweeps after blocking exchanges, bit for bit. Returns the bonds broken (each once).
std::int64_t overlapped_sweeps(const LpsKernel& k, const Breaking* br, const Decomposed& d, const GhostsInFlight& u_ghosts,
                               Vec3Array& f, double* w) {
  std::vector<double> theta, p;
  const std::int64_t broken =
      sweep_overlapped(u_ghosts, [&](RowSubset rows) { return dilatation_sweep(k, br, theta, p, rows); });
  // P_j of the ghosts, after their owners broke their rows: both ends of a crossing bond broke it
  // in this sweep (the same stretch from exact copies of u), so P_j is the serial one.
  const GhostsInFlight p_ghosts = d.send_ghosts(p);
  sweep_overlapped(p_ghosts, [&](RowSubset rows) { force_sweep(k, theta, p, f, w, rows); });
  return broken;
}

Breaking breaking_of(Model& m, double* lost) {
  return Breaking{m.material.critical_pair.data(), m.block_index.data(), m.material.blocks, m.no_fail.data(), lost};
}

}  // namespace

void LpsModel::add_force(const Model& model, const Vec3Array& u, Vec3Array& f, double* w) const {
  const LpsKernel k(*this, model, u);
  std::vector<double> theta, p;
  dilatation_sweep(k, nullptr, theta, p);
  if (decomposed_) decomposed_->update_ghosts(p);  // P_j of the ghosts, for t_ij + t_ji
  force_sweep(k, theta, p, f, w);
}

BreakReport LpsModel::break_bonds_and_add_force(Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                                                bool want_energy, double* lost_per_node) const {
  const LpsKernel k(*this, model, u);
  std::vector<double> theta, p, lost(want_energy ? model.nodes.size() : 0, 0.0);
  const Breaking br = breaking_of(model, want_energy ? lost.data() : nullptr);
  BreakReport r;
  r.broken = dilatation_sweep(k, model.material.can_break() ? &br : nullptr, theta, p);
  // P_j of the ghosts, after their owners broke their rows: both ends of a crossing bond broke it
  // in this sweep (the same stretch from exact copies of u), so P_j is the serial one.
  if (decomposed_) decomposed_->update_ghosts(p);
  force_sweep(k, theta, p, f, w);
  if (lost_per_node && want_energy) {  // the caller sums the shares (materials/bond_model.hpp)
    std::copy(lost.begin(), lost.end(), lost_per_node);
    return r;
  }
  if (r.broken > 0)
    r.energy += exact_sum(lost);  // exact (core/exact_sum.hpp): the same for any thread and rank count
  return r;
}

void LpsModel::add_force_overlapped(const Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                                    const GhostsInFlight& u_ghosts) const {
  if (!decomposed_) return BondModel::add_force_overlapped(model, u, f, w, u_ghosts);
  overlapped_sweeps(LpsKernel(*this, model, u), nullptr, *decomposed_, u_ghosts, f, w);
}

BreakReport LpsModel::break_bonds_and_add_force_overlapped(Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                                                           bool want_energy, double* lost_per_node,
                                                           const GhostsInFlight& u_ghosts) const {
  // The shares of the lost energy stay per node (lost_per_node): a split sweep gives no whole sum.
  if (!decomposed_ || !lost_per_node || !want_energy)
    return BondModel::break_bonds_and_add_force_overlapped(model, u, f, w, want_energy, lost_per_node, u_ghosts);
  std::fill(lost_per_node, lost_per_node + model.nodes.size(), 0.0);
  const Breaking br = breaking_of(model, lost_per_node);
  BreakReport r;
  r.broken = overlapped_sweeps(LpsKernel(*this, model, u), model.material.can_break() ? &br : nullptr, *decomposed_,
                               u_ghosts, f, w);
  return r;
}

BreakReport LpsModel::break_bonds(Model& model, const Vec3Array& u, bool want_energy) const {
  BreakReport r;
  if (!model.material.can_break()) return r;
  const LpsKernel k(*this, model, u);
  std::vector<double> theta, p, lost(want_energy ? model.nodes.size() : 0, 0.0);
  const Breaking br = breaking_of(model, want_energy ? lost.data() : nullptr);
  r.broken = dilatation_sweep(k, &br, theta, p);
  if (r.broken > 0)
    r.energy += exact_sum(lost);
  return r;
}

StretchRatio LpsModel::stretch_ratio(const Model& model, const Vec3Array& u) const {
  StretchRatio out;
  if (!model.material.can_break()) return out;
  const LpsKernel k(*this, model, u);
  const Breaking br = breaking_of(const_cast<Model&>(model), nullptr);  // read only: no flag is set here
  double largest = 0.0;
  std::int64_t over = 0;  // a maximum and an integer sum: exact in any order of rows and threads
#pragma omp parallel for schedule(static) reduction(max : largest) reduction(+ : over)
  for (std::int64_t i = 0; i < k.nodes; ++i) {
    if (br.no_fail[i]) continue;  // as dilatation_row: a no-fail node breaks nothing
    const double* s0_row = br.s0_pair + br.block[i] * br.blocks;
    for (std::int64_t q = k.offsets[i]; q < k.offsets[i + 1]; ++q) {
      const std::int64_t j = k.neighbour[q];
      if (k.broken[q] || br.no_fail[j]) continue;
      const LpsKernel::Bond t = k.bond(i, q);
      const double s0 = s0_row[br.block[j]];
      // The stretch (y − |ξ|)/|ξ| over s0, and the criterion itself (Bond::over) for the count.
      if (s0 > 0.0 && s0 < std::numeric_limits<double>::infinity()) largest = std::max(largest, t.raw / (s0 * t.length));
      if (i < j && t.over(s0)) ++over;
    }
  }
  out.largest = largest;
  out.over = over;
  return out;
}

std::vector<double> LpsModel::strain_energy_density(const Model& model, const Vec3Array& u) const {
  const LpsKernel k(*this, model, u);
  std::vector<double> w(model.nodes.size(), 0.0);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < k.nodes; ++i) {
    double st = 0.0, mi = 0.0;
    k.row_sums(i, st, mi);
    w[static_cast<std::size_t>(i)] = k.row_energy(i, k.theta_of(i, st));
  }
  return w;
}

std::vector<double> LpsModel::dilatation(const Model& model, const Vec3Array& u) const {
  const LpsKernel k(*this, model, u);
  std::vector<double> theta, p;
  dilatation_sweep(k, nullptr, theta, p);
  return theta;
}

// δf = J(u)·x in the same two sweeps: δθ_i = (d/m_i) Σ ω|ξ| (n·δη) V_j, δP_i = γ_i δθ_i with
// γ_i = P_i/θ_i (m'_i does not depend on u), and per bond, n = e/y, δη = x_j − x_i,
//   δf_i += V_j { ω[|ξ|(δP_i + δP_j) + (a_i + a_j) n·δη] n + T (δη − n (n·δη))/y },
// T = t_ij + t_ji (the rotation of a loaded bond). Bonds crushed to a point (y = 0) carry no force
// and have no direction: left out, as the kernel leaves their force out.
namespace {

// J·x's sweep 1 over `rows`: P_i at u and δP_i = γ_i δθ_i (P is linear in θ at fixed m'), which
// read u and x of the row's far ends. p and dp are sized to the nodes; only the rows' entries are set.
void jacobian_dilatation_sweep(const LpsKernel& k, const Vec3Array& x, std::vector<double>& p, std::vector<double>& dp,
                               RowSubset rows) {
  const std::int64_t count = rows.size(k.nodes);
#pragma omp parallel for schedule(static)
  for (std::int64_t r = 0; r < count; ++r) {
    const std::int64_t i = rows.at(r);
    double st = 0.0, sd = 0.0, sm = 0.0;
    for (std::int64_t q = k.offsets[i]; q < k.offsets[i + 1]; ++q) {
      if (k.broken[q]) continue;
      const std::int64_t j = k.neighbour[q];
      const LpsKernel::Bond t = k.bond(i, q);
      const double along = t.y > 0.0 ? ((x[0][j] - x[0][i]) * t.e0 + (x[1][j] - x[1][i]) * t.e1 +
                                        (x[2][j] - x[2][i]) * t.e2) * t.inv_y
                                     : 0.0;
      st += t.omega * t.length * t.ext * t.vj;
      sd += t.omega * t.length * along * t.vj;
      sm += t.omega * t.length * t.length * t.vj;
    }
    const double theta = k.theta_of(i, st);
    p[static_cast<std::size_t>(i)] = k.p_of(i, theta, sm);
    dp[static_cast<std::size_t>(i)] = k.p_of(i, k.theta_of(i, sd), sm);  // P is linear in θ at fixed m'
  }
}

// J·x's sweep 2 over `rows`: y_i += δf_i from the row's bonds and P, δP of both ends.
void jacobian_force_sweep(const LpsKernel& k, const Vec3Array& x, const std::vector<double>& p,
                          const std::vector<double>& dp, Vec3Array& y, RowSubset rows) {
  const std::int64_t count = rows.size(k.nodes);
#pragma omp parallel for schedule(static)
  for (std::int64_t r = 0; r < count; ++r) {
    const std::int64_t i = rows.at(r);
    const auto iu = static_cast<std::size_t>(i);
    double s0 = 0.0, s1 = 0.0, s2 = 0.0;
    for (std::int64_t q = k.offsets[i]; q < k.offsets[i + 1]; ++q) {
      if (k.broken[q]) continue;
      const std::int64_t j = k.neighbour[q];
      const auto ju = static_cast<std::size_t>(j);
      const LpsKernel::Bond t = k.bond(i, q);
      if (!(t.y > 0.0)) continue;
      const double n0 = t.e0 * t.inv_y, n1 = t.e1 * t.inv_y, n2 = t.e2 * t.inv_y;
      const double x0 = x[0][ju] - x[0][iu], x1 = x[1][ju] - x[1][iu], x2 = x[2][ju] - x[2][iu];
      const double along = n0 * x0 + n1 * x1 + n2 * x2;
      const double ai_aj = k.a[i] + k.a[j];
      const double dt = t.omega * (t.length * (dp[iu] + dp[ju]) + ai_aj * along);
      const double tt = t.omega * (t.length * (p[iu] + p[ju]) + ai_aj * t.ext);
      const double turn = tt * t.inv_y;
      s0 += t.vj * (dt * n0 + turn * (x0 - n0 * along));
      s1 += t.vj * (dt * n1 + turn * (x1 - n1 * along));
      s2 += t.vj * (dt * n2 + turn * (x2 - n2 * along));
    }
    y[0][iu] += s0;
    y[1][iu] += s1;
    y[2][iu] += s2;
  }
}

}  // namespace

// δf = J(u)·x in the same two sweeps: δθ_i = (d/m_i) Σ ω|ξ| (n·δη) V_j, δP_i = γ_i δθ_i with
// γ_i = P_i/θ_i (m'_i does not depend on u), and per bond, n = e/y, δη = x_j − x_i,
//   δf_i += V_j { ω[|ξ|(δP_i + δP_j) + (a_i + a_j) n·δη] n + T (δη − n (n·δη))/y },
// T = t_ij + t_ji (the rotation of a loaded bond). Bonds crushed to a point (y = 0) carry no force
// and have no direction: left out, as the kernel leaves their force out.
void LpsModel::add_jacobian_product(const Model& model, const Vec3Array& u, const Vec3Array& x, Vec3Array& y) const {
  const LpsKernel k(*this, model, u);
  const auto n = static_cast<std::size_t>(k.nodes);
  std::vector<double> p(n), dp(n);
  jacobian_dilatation_sweep(k, x, p, dp, RowSubset{});
  // A decomposed run (issue 15): the ghosts' P and δP from their owners, in one exchange.
  if (decomposed_) decomposed_->update_ghosts(NodeColumns(p).add(dp));
  jacobian_force_sweep(k, x, p, dp, y, RowSubset{});
}

// Both sweeps overlapped with the exchanges they need (parallel/row_split.hpp), as the force's
// (overlapped_sweeps): sweep 1 over the interior rows while x's ghosts travel, then the boundary
// rows; P and δP of every owned node then travel together while sweep 2 goes over the interior
// rows, then over the boundary rows. The same y as add_jacobian_product after blocking exchanges.
void LpsModel::add_jacobian_product_overlapped(const Model& model, const Vec3Array& u, const Vec3Array& x, Vec3Array& y,
                                               const GhostsInFlight& x_ghosts) const {
  if (!decomposed_) return BondModel::add_jacobian_product_overlapped(model, u, x, y, x_ghosts);
  const LpsKernel k(*this, model, u);
  const auto n = static_cast<std::size_t>(k.nodes);
  std::vector<double> p(n, 0.0), dp(n, 0.0);
  sweep_overlapped(x_ghosts, [&](RowSubset rows) { jacobian_dilatation_sweep(k, x, p, dp, rows); });
  const GhostsInFlight p_ghosts = decomposed_->send_ghosts(NodeColumns(p).add(dp));
  sweep_overlapped(p_ghosts, [&](RowSubset rows) { jacobian_force_sweep(k, x, p, dp, y, rows); });
}

}  // namespace pd
