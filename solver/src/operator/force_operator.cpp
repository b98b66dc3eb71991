// The operator: the scene's force, breaking, linearisation, prescribed motion and energy ledger.
#include "operator/force_operator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "core/error.hpp"
#include "core/stability.hpp"
#include "forces/damping.hpp"
#include "parallel/local_model.hpp"
#include "parallel/node_sum.hpp"

namespace pd {

ForceOperator::ForceOperator(Model& model) : model_(model) {
  // Build the terms the scene needs, once; remember the power order beside the force order.
  std::vector<std::pair<int, const ForceTerm*>> by_power;
  for (const ForceTermEntry& entry : force_term_registry()) {
    std::unique_ptr<ForceTerm> term = entry.make(model_);
    built_.push_back(term.get());
    if (term) {
      by_power.emplace_back(entry.power_order, term.get());
      terms_.push_back(std::move(term));
    }
  }
  std::stable_sort(by_power.begin(), by_power.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& item : by_power) power_terms_.push_back(item.second);
}

void ForceOperator::set_decomposed(const Decomposed* d) {
  decomposed_ = d;
  model_.bond_model->set_decomposed(d);
  for (const auto& term : terms_) term->set_decomposed(d);
}

void ForceOperator::evaluate(State& s, double t) const {
  for (auto& fc : s.f) std::fill(fc.begin(), fc.end(), 0.0);
  if (!decomposed_) {
    model_.bond_model->add_force(model_, s.u, s.f, s.w.data());
  } else {
    // The ghosts' u travel while the law sweeps the rows that read none (parallel/row_split.hpp).
    const GhostsInFlight u_ghosts = decomposed_->send_ghosts(s.u);
    model_.bond_model->add_force_overlapped(model_, s.u, s.f, s.w.data(), u_ghosts);
    u_ghosts.wait();  // the terms below read the ghosts' u (a law waits before its boundary rows anyway)
  }
  s.term_energies.assign(term_energy_names().size(), 0.0);  // a term the scene lacks stays 0
  for (const auto& term : terms_) term->add_force(s, t);
}

BreakReport ForceOperator::break_bonds_and_evaluate(State& s, double t) {
  for (auto& fc : s.f) std::fill(fc.begin(), fc.end(), 0.0);
  BreakReport report;
  if (!decomposed_) report = model_.bond_model->break_bonds_and_add_force(model_, s.u, s.f, s.w.data(), true);
  else report = break_on_piece(s.u, s.f, s.w.data());
  s.term_energies.assign(term_energy_names().size(), 0.0);  // a term the scene lacks stays 0
  for (const auto& term : terms_) term->add_force(s, t);
  return report;
}

BreakReport ForceOperator::break_bonds(State& s) {
  if (!decomposed_) return model_.bond_model->break_bonds(model_, s.u, true);
  // The breaking of break_bonds_and_evaluate into scratch force arrays: the same flags as the law's
  // break_bonds (bond_model.hpp), with each node's share of the lost energy kept for the exact sum.
  Vec3Array f = make_vec3(s.size());
  std::vector<double> w(s.size(), 0.0);
  return break_on_piece(s.u, f, w.data());
}

BreakReport ForceOperator::break_on_piece(Vec3Array& u, Vec3Array& f, double* w) {
  // Both ends of a bond that crosses ranks compute the same stretch from exact copies of the
  // displacements, so both break it in this call; the i < j copy counts it, on one rank only.
  // A law's declared per-node history with `halo` (LAMMPS's α rule: a bond's threshold
  // min(s0_i, s0_j) reads its ghost end's s0), which the previous pass updated on the owner only (a
  // ghost's empty row leaves +inf): it travels with u, in the same exchange (one message per
  // neighbour), while the law sweeps the rows that read no ghost (parallel/row_split.hpp).
  const GhostsInFlight ghosts = decomposed_->send_ghosts(breaking_ghost_values(u));
  lost_.assign(u[0].size(), 0.0);
  BreakReport report =
      model_.bond_model->break_bonds_and_add_force_overlapped(model_, u, f, w, true, lost_.data(), ghosts);
  ghosts.wait();  // the terms read the ghosts' u (a law waits before its boundary rows anyway)
  reduce_break_report(report);
  return report;
}

void ForceOperator::reduce_break_report(BreakReport& report) {
  // Both ends of a bond that crosses ranks break it in the same pass; the i < j copy counts it and
  // holds its energy, on one rank only. The count and the energy the broken bonds held, summed
  // exactly over the owned nodes as the serial path sums it, go in one reduction.
  ExactSum energy;
  for (std::int32_t l : decomposed_->piece().owned_local) energy.add(lost_[static_cast<std::size_t>(l)]);
  std::int64_t broken = report.broken;
  decomposed_->reduce(&energy, 1, &broken, 1);
  report.broken = broken;
  report.energy = broken > 0 ? energy.value() : 0.0;
}

NodeColumns ForceOperator::breaking_ghost_values(Vec3Array& u) const {
  NodeColumns values(u);
  return add_halo_state(values, model_.state_arrays);
}

StretchRatio ForceOperator::stretch_ratio(State& s) const {
  if (!decomposed_) return model_.bond_model->stretch_ratio(model_, s.u);
  // The ratio reads what the breaking test reads of a ghost (break_on_piece): u and the declared history.
  decomposed_->update_ghosts(breaking_ghost_values(s.u));
  StretchRatio r = model_.bond_model->stretch_ratio(model_, s.u);  // a ghost's row is empty: owned rows only
  r.largest = -decomposed_->minimum(-r.largest);  // the maximum over the ranks, exactly
  r.over = decomposed_->total(r.over);             // each bond counted on one rank (its i < j copy)
  return r;
}

bool ForceOperator::any_broken() const {
  const auto& broken = model_.bonds.broken;
  const bool here = std::any_of(broken.begin(), broken.end(), [](std::uint8_t b) { return b != 0; });
  return decomposed_ ? decomposed_->total(here ? 1 : 0) > 0 : here;
}

FreeDofs ForceOperator::free_dofs(int dimension) const {
  if (!decomposed_) return FreeDofs::of(size(), dimension, fixed());
  // A ghost is treated as prescribed: its row, and so its unknowns, belong to its owner.
  auto held = fixed();
  const auto& owned = decomposed_->piece().owned;
  for (auto& component : held)
    for (std::size_t i = 0; i < component.size(); ++i)
      if (!owned[i]) component[i] = 1;
  return FreeDofs::of(size(), dimension, held);
}

void ForceOperator::apply_jacobian(const State& s, double t, const Vec3Array& x, Vec3Array& y) const {
  for (auto& yc : y) std::fill(yc.begin(), yc.end(), 0.0);
  if (!decomposed_) {
    model_.bond_model->add_jacobian_product(model_, s.u, x, y);
    for (const auto& term : terms_) term->add_jacobian_product(s, t, x, y);
    return;
  }
  // x's ghosts travel while the law sweeps the rows that read none (parallel/row_split.hpp).
  ghosted_x_ = x;
  const GhostsInFlight x_ghosts = decomposed_->send_ghosts(ghosted_x_);
  model_.bond_model->add_jacobian_product_overlapped(model_, s.u, ghosted_x_, y, x_ghosts);
  x_ghosts.wait();
  for (const auto& term : terms_) term->add_jacobian_product(s, t, ghosted_x_, y);
}

bool ForceOperator::has_assembled_stiffness(const State& s, double t) const {
  const Model& m = model_;
  if (m.nodes.size() == 0) return true;
  std::vector<double> probe(9 * (m.bonds.offsets.size() > 1 ? static_cast<std::size_t>(m.bonds.offsets[1]) : 0) + 9);
  double diagonal[9] = {};
  if (!m.bond_model->bond_tangent_row(m, s.u, 0, probe.data())) return false;
  for (const auto& term : terms_)
    if (!term->add_tangent_diagonal(s, t, 0, diagonal)) return false;
  return true;
}

std::string ForceOperator::missing_assembled_stiffness(const State& s, double t) const {
  if (has_assembled_stiffness(s, t)) return "";
  const Model& m = model_;
  std::vector<double> probe(9 * (m.bonds.offsets.size() > 1 ? static_cast<std::size_t>(m.bonds.offsets[1]) : 0) + 9);
  if (!m.bond_model->bond_tangent_row(m, s.u, 0, probe.data()))
    return "the state-based material " + m.bond_model->name() + " (its force on a node depends on the neighbours' "
           "neighbours, so its tangent is not assembled)";
  return "contact";  // the one term without add_tangent_diagonal
}

bool ForceOperator::stiffness_diagonal_blocks(const State& s, double t, const FreeDofs& dofs,
                                              std::vector<std::int64_t>& first, std::vector<double>& blocks) const {
  const Model& m = model_;
  const std::size_t n = m.nodes.size();
  // A bond-based law's block is minus the sum of its row's bond blocks; a state-based law gives
  // every node's block itself (BondModel::jacobian_diagonal_blocks), or none.
  std::vector<double> law_blocks;
  bool bond_based = true;
  {
    std::vector<double> probe(9 * (m.bonds.offsets.size() > 1 ? static_cast<std::size_t>(m.bonds.offsets[1]) : 0) + 9);
    if (n > 0 && !m.bond_model->bond_tangent_row(m, s.u, 0, probe.data(), true)) {
      if (!m.bond_model->jacobian_diagonal_blocks(m, s.u, law_blocks, true)) return false;
      bond_based = false;
    }
  }
  // Groups: the nodes with free components, in dof order.
  first.clear();
  std::vector<std::int64_t> node_of;
  for (std::size_t k = 0; k < dofs.size(); ++k)
    if (k == 0 || dofs.node[k] != dofs.node[k - 1]) first.push_back(static_cast<std::int64_t>(k)), node_of.push_back(dofs.node[k]);
  first.push_back(static_cast<std::int64_t>(dofs.size()));
  const auto groups = static_cast<std::int64_t>(node_of.size());
  blocks.assign(static_cast<std::size_t>(9 * groups), 0.0);
  const auto& off = m.bonds.offsets;
  for (const auto& term : terms_) term->prepare_jacobian_diagonal(s, t);  // collective on a decomposed run
#pragma omp parallel
  {
    std::vector<double> row;
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t g = 0; g < groups; ++g) {
      const auto i = static_cast<std::size_t>(node_of[static_cast<std::size_t>(g)]);
      double diagonal[9] = {};
      if (bond_based) {
        row.assign(static_cast<std::size_t>(9 * (off[i + 1] - off[i])), 0.0);
        m.bond_model->bond_tangent_row(m, s.u, i, row.data(), true);
        // ∂f_i/∂u_i = −Σ_j ∂f_i/∂u_j for a bond-based law
        for (std::size_t b = 0; b < row.size() / 9; ++b)
          for (int q = 0; q < 9; ++q) diagonal[q] -= row[9 * b + static_cast<std::size_t>(q)];
      } else {
        std::copy(&law_blocks[9 * i], &law_blocks[9 * i] + 9, diagonal);
      }
      for (const auto& term : terms_) term->add_jacobian_diagonal(s, t, i, diagonal, true);
      // K's block over the node's free components: −V_i ∂f_i/∂u_i.
      const auto at = static_cast<std::size_t>(first[static_cast<std::size_t>(g)]);
      const auto k = static_cast<std::size_t>(first[static_cast<std::size_t>(g) + 1]) - at;
      double* out = &blocks[9 * static_cast<std::size_t>(g)];
      for (std::size_t a = 0; a < k; ++a)
        for (std::size_t b = 0; b < k; ++b)
          out[3 * a + b] = -m.nodes.volume[i] * diagonal[3 * dofs.component[at + a] + dofs.component[at + b]];
    }
  }
  return true;
}

SparseMatrix ForceOperator::assemble_stiffness(const State& s, double t, const FreeDofs& dofs, bool definite) const {
  const Model& m = model_;
  const auto n = static_cast<std::int64_t>(m.nodes.size());
  SparseMatrix K;
  K.rows = -1;
  if (!has_assembled_stiffness(s, t)) return K;  // an assembled form exists only if the law and every term have one
  const auto& off = m.bonds.offsets;
  const auto dof = [&](std::size_t node, int d) { return dofs.index[3 * node + static_cast<std::size_t>(d)]; };
  // Pass 1: the pattern. Row (i, d) has a column for every free component of i and of its bonded
  // nodes (broken bonds too: the pattern never changes).
  std::vector<std::int64_t> free_of(static_cast<std::size_t>(n), 0);
  for (std::int64_t i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d) free_of[static_cast<std::size_t>(i)] += dof(static_cast<std::size_t>(i), d) >= 0;
  K.rows = static_cast<std::int64_t>(dofs.size());
  K.row_start.assign(dofs.size() + 1, 0);
  for (std::size_t r = 0; r < dofs.size(); ++r) {
    const auto i = static_cast<std::size_t>(dofs.node[r]);
    std::int64_t count = free_of[i];
    for (std::int64_t k = off[i]; k < off[i + 1]; ++k) count += free_of[static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)])];
    K.row_start[r + 1] = K.row_start[r] + count;
  }
  K.column.resize(static_cast<std::size_t>(K.row_start.back()));
  K.value.resize(K.column.size());
  // Pass 2: the values, node by node (each node fills only its own rows).
#pragma omp parallel
  {
    std::vector<double> blocks;
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t i64 = 0; i64 < n; ++i64) {
      const auto i = static_cast<std::size_t>(i64);
      if (free_of[i] == 0) continue;
      const std::int64_t bonds = off[i + 1] - off[i];
      blocks.assign(static_cast<std::size_t>(9 * bonds), 0.0);
      m.bond_model->bond_tangent_row(m, s.u, i, blocks.data(), definite);
      double diagonal[9] = {};
      for (std::int64_t b = 0; b < bonds; ++b)
        for (int q = 0; q < 9; ++q) diagonal[q] -= blocks[static_cast<std::size_t>(9 * b + q)];
      for (const auto& term : terms_) term->add_tangent_diagonal(s, t, i, diagonal);
      const double volume = m.nodes.volume[i];
      for (int d = 0; d < 3; ++d) {
        const std::int64_t r = dof(i, d);
        if (r < 0) continue;
        std::int64_t at = K.row_start[static_cast<std::size_t>(r)];
        // Columns in node order: the bonded nodes below i, i itself, those above (rows ascend).
        bool self_done = false;
        auto put_node = [&](std::size_t j, const double* block) {
          for (int e = 0; e < 3; ++e) {
            const std::int64_t col = dof(j, e);
            if (col < 0) continue;
            K.column[static_cast<std::size_t>(at)] = col;
            K.value[static_cast<std::size_t>(at)] = -volume * block[3 * d + e];
            ++at;
          }
        };
        for (std::int64_t b = 0; b < bonds; ++b) {
          const auto j = static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(off[i] + b)]);
          if (!self_done && j > i) put_node(i, diagonal), self_done = true;
          put_node(j, &blocks[static_cast<std::size_t>(9 * b)]);
        }
        if (!self_done) put_node(i, diagonal);
      }
    }
  }
  return K;
}

void ForceOperator::start(State& s, double t) const {
  impose_prescribed_motion(s, t);
  evaluate(s, t);
  update_work(s, t, 0.0);
}

void ForceOperator::impose_prescribed_motion(State& s, double t) const {
  for (const auto& p : model_.conditions.prescribed) {
    auto& u = s.u[static_cast<std::size_t>(p.component)];
    auto& v = s.v[static_cast<std::size_t>(p.component)];
    const bool disp = p.kind == Kinematic::displacement;
    const double value = p.table.value(t);
    const double rate = disp ? p.table.slope(t) : value;
    for (std::int32_t i : p.nodes) {
      if (disp) u[static_cast<std::size_t>(i)] = value;
      v[static_cast<std::size_t>(i)] = rate;
    }
  }
}

void ForceOperator::advance_prescribed_motion(const Vec3Array& u_from, Vec3Array& u_to, Vec3Array& v_to, double t,
                                              double t1, double dt, bool end_velocity) const {
  for (const auto& p : model_.conditions.prescribed) {
    const auto c = static_cast<std::size_t>(p.component);
    if (p.kind == Kinematic::displacement) {
      const double u1 = p.table.value(t1), mean_v = (u1 - p.table.value(t)) / dt;
      for (std::int32_t i : p.nodes) {
        u_to[c][static_cast<std::size_t>(i)] = u1;
        v_to[c][static_cast<std::size_t>(i)] = mean_v;
      }
    } else {
      // Velocity table: u^{n+1} = u^n + ∫v dt exactly; v is the mean over the step, so that
      // u^{n+1} = u^n + Δt·v^{n+½} holds for it as for the free components of Verlet.
      const double du = p.table.integral(t, t1), v_step = end_velocity ? p.table.value(t1) : du / dt;
      for (std::int32_t i : p.nodes) {
        u_to[c][static_cast<std::size_t>(i)] = u_from[c][static_cast<std::size_t>(i)] + du;
        v_to[c][static_cast<std::size_t>(i)] = v_step;
      }
    }
  }
}

void ForceOperator::impose_prescribed_velocity(Vec3Array& v, double t1) const {
  for (const auto& p : model_.conditions.prescribed)
    if (p.kind == Kinematic::velocity) {
      auto& vc = v[static_cast<std::size_t>(p.component)];
      const double v1 = p.table.value(t1);
      for (std::int32_t i : p.nodes) vc[static_cast<std::size_t>(i)] = v1;
    }
}

namespace {

// Node i's terms of the kinetic energy ½ ρ V |v|² and of the strain energy W_i V_i [J].
double kinetic_term(const Model& m, const State& s, std::size_t i) {
  return 0.5 * m.density[i] * m.nodes.volume[i] * (s.v[0][i] * s.v[0][i] + s.v[1][i] * s.v[1][i] + s.v[2][i] * s.v[2][i]);
}
double strain_term(const Model& m, const State& s, std::size_t i) { return s.w[i] * m.nodes.volume[i]; }

}  // namespace

double ForceOperator::kinetic_energy(const State& s) const {
  return sum_over_nodes(decomposed_, s.size(), [&](std::size_t i) { return kinetic_term(model_, s, i); });
}

double ForceOperator::strain_energy(const State& s) const {
  return sum_over_nodes(decomposed_, s.size(), [&](std::size_t i) { return strain_term(model_, s, i); });
}

ForceOperator::KineticAndStrain ForceOperator::kinetic_and_strain_energy(const State& s) const {
  // The terms of kinetic_energy and strain_energy, each summed exactly: the same two values, bit for bit.
  const std::array<double, 2> e = sums_over_nodes<2>(decomposed_, s.size(), [&](std::size_t i) {
    return std::array<double, 2>{kinetic_term(model_, s, i), strain_term(model_, s, i)};
  });
  return KineticAndStrain{e[0], e[1]};
}

double ForceOperator::external_power(const State& s, double t) const {
  // The force terms' powers first, in power order, each reduced by the term itself (it knows the
  // decomposition: ForceTerm::set_decomposed), then one exact sum per support, continuing the last
  // (parallel/node_sum.hpp): the same bits serially and on any number of ranks.
  double p = 0.0;
  for (const ForceTerm* term : power_terms_) term->add_power(s, t, p);
  for (const auto& bc : model_.conditions.prescribed) {
    const auto c = static_cast<std::size_t>(bc.component);
    const double a = bc.kind == Kinematic::velocity ? bc.table.slope(t) : 0.0;
    p = sum_over_set(decomposed_, bc.nodes, p, [&](std::size_t i) {
      const double reaction = model_.density[i] * a - s.f[c][i];  // force density the support applies
      return model_.nodes.volume[i] * reaction * s.v[c][i];
    });
  }
  return p;
}

void ForceOperator::update_work(State& s, double t, double dt) const {
  const double pe = external_power(s, t);
  const double pd = damping_power(model_.damping, model_.density, model_.nodes.volume, s.v, model_.conditions.fixed, decomposed_);
  s.external_work += 0.5 * dt * (s.external_power + pe);
  s.damping_work += 0.5 * dt * (s.damping_power + pd);
  s.external_power = pe;
  s.damping_power = pd;
}

double ForceOperator::stable_time_step() const {
  // A ghost's row is empty, so the local minimum is over owned nodes; min is exact in any order.
  const double dt = pd::stable_time_step(model_);
  return decomposed_ ? decomposed_->minimum(dt) : dt;
}

double ForceOperator::exact_time_step() const {
  // On a piece: Lanczos on the owned rows, collective (core/stability.hpp).
  return pd::exact_time_step(model_, decomposed_);
}

std::vector<std::string> ForceOperator::work_plan(const Case& c) const {
  std::vector<std::string> lines;
  // A piece's rows hold every bond of its owned nodes: summed over the ranks, each bond twice.
  const auto directed = static_cast<std::int64_t>(model_.bonds.directed());
  lines.push_back("work: bond forces over " + std::to_string((decomposed_ ? decomposed_->total(directed) : directed) / 2) +
                  " bonds, partial volume " +
                  c.partial_volume + (c.dimension == 2 ? "; 2D (cell grids one bin thick)" : "; 3D"));
  // Only with the correction: run.log of a case without it is unchanged. Decomposed, the range is
  // over every rank's rows (min and max are exact in any order); a piece may hold no bond at all.
  const bool corrected =
      decomposed_ ? decomposed_->total(model_.bonds.corrected() ? 1 : 0) > 0 : model_.bonds.corrected();
  if (corrected) {
    const auto& g = model_.bonds.surface_factor;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (double gk : g) lo = std::min(lo, gk), hi = std::max(hi, gk);
    if (decomposed_) lo = decomposed_->minimum(lo), hi = -decomposed_->minimum(-hi);
    char range[96];
    std::snprintf(range, sizeof range, "factors g from %.4g to %.4g", lo, hi);
    lines.push_back("work: surface correction " + c.surface_correction + " (Le & Bobaru 2018), bond " + range);
  }
  const auto& registry = force_term_registry();
  for (std::size_t k = 0; k < registry.size(); ++k) {
    if (built_[k]) {
      for (const auto& line : built_[k]->work_plan()) lines.push_back(line);
    } else if (const std::string line = registry[k].absent(model_, c); !line.empty()) {
      lines.push_back(line);
    }
  }
  lines.push_back(can_break() ? "work: breakage test after every step"
                              : "work: no breakage test (every block unbreakable)");
  return lines;
}

}  // namespace pd
