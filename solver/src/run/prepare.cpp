// The prepare phase of a run: case, nodes, model, time step, integrator (run/prepare.hpp).
#include "run/prepare.hpp"

#include <omp.h>
#ifdef __GLIBC__
#include <malloc.h>  // malloc_trim
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "core/error.hpp"
#include "core/stability.hpp"
#include "core/time_step_rule.hpp"
#include "forces/indenter.hpp"
#include "io/case_reader.hpp"
#include "io/node_file.hpp"
#include "materials/bond_model.hpp"
#include "parallel/local_model.hpp"
#include "parallel/session.hpp"
#include "run/schedule.hpp"
#include "run/text.hpp"

namespace pd {

namespace {

using Clock = std::chrono::steady_clock;

// A material whose constants come out unusable (overflow of c for extreme E, δ or thickness).
void check_materials(const Prepared& p) {
  for (std::size_t b = 0; b < p.model.material.block.size(); ++b) {
    const auto& k = p.model.material.block[b];
    if (!std::isfinite(k.micromodulus) || !(k.micromodulus > 0.0) || !(k.critical_stretch > 0.0))
      throw Error(p.c.file.string() + ": blocks[" + std::to_string(b) + "] '" + p.c.blocks[b].name +
                  "': the material gives micromodulus c = " + format("%.6g", k.micromodulus) +
                  " and critical stretch s0 = " + format("%.6g", k.critical_stretch) +
                  " (need finite c > 0 and s0 > 0): check density, youngs_modulus, fracture_energy, horizon and thickness");
  }
}

// A step above eq. 2.5 (a fixed dt, or safety_factor > 1) is judged at set-up against the exact
// linear limit 2/ω_max (core/stability, Lanczos), computed only then: above it the run will blow up,
// which before was found only thousands of steps later (issue 17, item 12). dt: exact with a
// safety factor ≤ 1 is below that limit by construction.
std::vector<std::string> step_warnings(Prepared& p) {
  const Case& c = p.c;
  if (!(p.dt > p.dt_stable) || (c.time.dt_rule == "exact" && c.time.safety_factor <= 1.0)) return {};
  const std::string what = c.time.dt_rule == "fixed" ? "the fixed dt " + format("%.6g", p.dt) + " s"
                                                      : "dt " + format("%.6g", p.dt) + " s (safety factor " +
                                                            format("%g", c.time.safety_factor) + ")";
  const double exact = p.exact_limit();
  if (std::isfinite(exact) && p.dt > exact)
    return {"warning: " + what + " is " + format("%.4g", p.dt / exact) + " × the exact stability limit 2/ω_max = " +
            format("%.6g", exact) + " s: the run will blow up; use time.safety_factor ≤ 1 (time.dt: stable or exact)"};
  return {"warning: " + what + " exceeds the stable time step of thesis eq. 2.5 (" + format("%.6g", p.dt_stable) +
          " s) but not the exact limit 2/ω_max = " + format("%.6g", exact) +
          " s: stable while the bonds stay linear; the run may blow up once they break or contact acts"};
}

// The time step: time.dt's rule (core/time_step_rule.hpp), the exact limit computed only if asked for.
void choose_dt(Prepared& p) {
  p.dt_stable = stable_time_step(p.model);
  p.dt = explicit_time_step(p.c, p.dt_stable, [&p] { return p.exact_limit(); });
}

// Nodes without a bond move freely: only loads and contact act on them (preprocess warns too, but
// the solver may be run alone). The count and the first one, −1 if none.
std::pair<std::int64_t, std::int64_t> isolated_nodes(const Model& model) {
  std::int64_t isolated = 0, first = -1;
  for (std::size_t i = 0; i < model.nodes.size(); ++i)
    if (model.bonds.offsets[i + 1] == model.bonds.offsets[i] && isolated++ == 0) first = static_cast<std::int64_t>(i);
  return {isolated, first};
}

// What is not decomposed yet is refused on several ranks, on every rank alike, before any output:
// a clear error instead of a silently wrong result (issue 15).
void check_decomposable(const Prepared& p) {
  const Case& c = p.c;
  const std::string ranks = std::to_string(world_ranks().size);
  std::string what;
  // pmb and lps are decomposed (lps fills its ghosts' P between its sweeps); a new law must say how.
  if (p.model.bond_model->name() != "pmb" && p.model.bond_model->name() != "lps")
    what = "blocks[].model: " + p.model.bond_model->name();
  // Decomposed: LAMMPS's α rule (the ghosts' s0 refreshed before each breaking pass), breaking_order:
  // lammps, surface_correction (its factors computed on each piece's owned rows, the ghosts' from
  // their owners), contact (forces/contact_on_piece, its linearised force too) with every integrator, and
  // every integrator: verlet, adaptive (its norms of eq. 2.6 are exact sums: core/exact_sum.hpp),
  // and quasi_static, implicit and mixed on their matrix-free path (their norms and CG's dot
  // products exact sums: parallel/dof_sums.hpp; linear_solver: direct is refused by the
  // integrator). dt: exact and fixed are decomposed too: the exact limit's Lanczos runs on the
  // pieces (core/stability.hpp) unless the ranks hold the whole model anyway.
  if (!what.empty())
    throw Error(c.file.string() + ": " + what + " is not decomposed over MPI ranks yet (issue 15; decomposed: the "
                "verlet, adaptive, quasi_static, implicit and mixed integrators with pmb and lps bonds, dt: stable, exact or fixed, "
                "breaking (breaking_order thesis or lammps, critical_stretch_alpha), surface_correction, contact with every "
                "integrator, displacement and velocity conditions, body forces, indenters, "
                "damping, frames, history, checkpoints and restarts on any rank count): run this case on one rank, without mpirun, or with mpirun -np 1 (here " + ranks + " ranks)");
}

}  // namespace

std::string whole_bonds_reason(const Case& c) {
  // Each rank holds only its own rows (issue 37 item 3): the exact limit — dt: exact, a step above
  // eq. 2.5, the adaptive step's default Δt_max, the indenters' depth bound — runs its Lanczos on the
  // pieces (Prepared::exact_limit); LPS's per-node constants and the surface correction's factors are
  // summed over each rank's owned rows, the ghosts' taken from their owners (LpsModel::set_decomposed,
  // core/surface_correction.hpp); mixed's load-path check joins the ranks' components
  // (integrators/load_path.hpp). One exception: LPS's Lanczos on a piece would need its second
  // sweep's partner values exchanged inside each product (core/stability.cpp refuses it), so LPS with
  // the exact limit keeps the whole list.
  const std::string law = c.blocks.empty() ? std::string("pmb") : c.blocks[0].model;
  if (law == "pmb") return "";
  std::string needs;
  if (c.time.dt_rule != "stable" || c.time.safety_factor > 1.0) needs = "time.dt " + c.time.dt_rule;
  else if (c.time.integrator == "adaptive" && !c.adaptive.dt_max) needs = "adaptive without dt_max";
  else if (!c.indenters.empty()) needs = "indenters";
  return needs.empty() ? "" : "blocks[].model " + law + " with " + needs + " (the exact limit)";
}

double Prepared::exact_limit() {
  // Lanczos on what this rank holds: the whole model serially and where every rank keeps the whole
  // bond list (no message then), else the rank's piece, collectively, with the same bits.
  if (!(dt_exact > 0.0))
    dt_exact = whole_bonds ? exact_time_step(model) : exact_time_step(decomposed->piece().model, decomposed.get());
  return dt_exact;
}

double Prepared::known_exact_limit() { return whole_bonds || dt_exact > 0.0 ? exact_limit() : std::nan(""); }

namespace {

template <class T>
std::int64_t bytes_of(const std::vector<T>& a) {
  return static_cast<std::int64_t>(a.capacity() * sizeof(T));
}

template <class T>
void release(std::vector<T>& a) {
  std::vector<T>().swap(a);  // clear() keeps the capacity
}

}  // namespace

std::int64_t node_data_bytes(const Model& m) {
  std::int64_t bytes = bytes_of(m.nodes.volume) + bytes_of(m.nodes.block) + bytes_of(m.density) +
                       bytes_of(m.block_index) + bytes_of(m.no_fail) + bytes_of(m.bonds.offsets) +
                       m.state_arrays.bytes();
  for (const auto& x : m.nodes.x) bytes += bytes_of(x);
  for (const auto& set : m.nodes.sets) bytes += bytes_of(set.member);
  for (const auto& pm : m.conditions.prescribed) bytes += bytes_of(pm.nodes);
  for (const auto& bf : m.conditions.body_forces) bytes += bytes_of(bf.nodes);
  for (const auto& fixed : m.conditions.fixed) bytes += bytes_of(fixed);
  return bytes;
}

namespace {

// Whether this rank may free the whole cloud's per-node arrays: rank 0 reads the whole model for
// the output (frames, history's reactions, checkpoints, node positions in messages); a rank that
// keeps the whole bond list keeps its nodes with it (the features that need it read both).
bool frees_whole_node_data(const Prepared& p) { return p.decomposed && !p.whole_bonds && !p.writes_output(); }

}  // namespace

void release_whole_rows_offsets(Prepared& p) {
  if (frees_whole_node_data(p)) release(p.model.bonds.offsets);  // Prepared::directed keeps the count
}

void release_whole_node_data(Prepared& p) {
  if (!frees_whole_node_data(p)) return;
  Model& m = p.model;
  for (auto& x : m.nodes.x) release(x);
  release(m.nodes.volume);
  release(m.nodes.block);
  for (auto& set : m.nodes.sets) release(set.member);  // the names stay
  release(m.density);
  release(m.block_index);
  release(m.no_fail);
  for (auto& pm : m.conditions.prescribed) release(pm.nodes);
  for (auto& bf : m.conditions.body_forces) release(bf.nodes);
  for (auto& fixed : m.conditions.fixed) release(fixed);
  // Freed heap pages inside the heap stay resident until reused or trimmed: hand them back now, so
  // that they do not add to the peak while the operator, the integrator and the state are made
  // (glibc; measured in docs/notes/2026-12-03-mpi-memory-exact-sums-overlap.md).
#ifdef __GLIBC__
  malloc_trim(0);
#endif
  // The declared per-node history stays: a checkpoint's gather is collective and every rank
  // gathers what it declares (run/loop.cpp write_restart); 8 bytes a node each, and only for a law
  // with history (PMB's α rule).
}

std::unique_ptr<Prepared> prepare(const RunOptions& opt) {
  auto p = std::make_unique<Prepared>();
  Case& c = p->c;
  c = read_case(opt.case_file);
  if (opt.end_time) c.time.end = *opt.end_time;
  if (opt.parallel_frames) c.output.parallel_frames = *opt.parallel_frames;
  if (opt.threads > 0) omp_set_num_threads(opt.threads);
  p->threads = omp_get_max_threads();
  Nodes nodes = read_node_file(c.nodes_file);
  for (const auto& name : c.node_sets)
    if (!nodes.find_set(name))
      throw Error(c.file.string() + ": node_sets: '" + name + "' has no array 'set_" + name + "' in " +
                  c.nodes_file.string());
  const auto build_start = Clock::now();
  // On several ranks each builds only its own rows when nothing needs the whole list (issue 15):
  // every rank counts every node's partners (8 bytes a node: the decomposition balances by them).
  p->whole_bonds = world_ranks().size == 1 || !whole_bonds_reason(c).empty();
  if (p->whole_bonds) {
    p->model = build_model(c, std::move(nodes));
  } else {
    p->model = build_model_without_bonds(c, std::move(nodes));
    p->model.bonds.offsets = count_bonds(p->model.nodes.x, bond_search_cutoff(c));
    // The case's law on the skeleton (no rows: a law precomputes nothing there, LpsModel's
    // constructor) only names the law the pieces make on their rows (for_piece).
    p->model.bond_model = material_registry().get(c.blocks.empty() ? std::string("pmb") : c.blocks[0].model).make(p->model);
    // The law's per-node history: each piece computes its own; the whole arrays (8 bytes a node
    // each) are where rank 0 gathers them for a checkpoint and a restart reads them back.
    declare_state(p->model, false);
  }
  p->build_seconds = std::chrono::duration<double>(Clock::now() - build_start).count();
  p->nodes = static_cast<std::int64_t>(p->model.nodes.size());
  p->directed = p->model.bonds.offsets.empty() ? 0 : p->model.bonds.offsets.back();
  std::tie(p->isolated, p->first_isolated) = isolated_nodes(p->model);
  check_materials(*p);

  if (p->whole_bonds) choose_dt(*p);
  p->max_steps = c.time.max_steps;
  if (opt.max_steps) p->max_steps = std::min(p->max_steps, *opt.max_steps);
  if (world_ranks().size > 1) {
    check_decomposable(*p);
    const auto rows_start = Clock::now();
    p->decomposed = p->whole_bonds ? decompose_over_ranks(p->model)
                                   : decompose_rows_over_ranks(p->model, bond_search_cutoff(c), c.cracks, c.surface_correction);
    if (!p->whole_bonds) {
      p->build_seconds += std::chrono::duration<double>(Clock::now() - rows_start).count();
      // Eq. 2.5 is a least over nodes of their rows' sums: each rank's over its owned rows, then the
      // least of those (exact), the serial value.
      p->dt_stable = p->decomposed->minimum(stable_time_step(p->decomposed->piece().model));
      p->dt = explicit_time_step(c, p->dt_stable, [&p] { return p->exact_limit(); });
    }
    // Before the operator, the integrator and the state are made, so that they do not add to it.
    release_whole_node_data(*p);
  }
  p->op = std::make_unique<ForceOperator>(p->decomposed ? p->decomposed->piece().model : p->model);
  if (p->decomposed) p->op->set_decomposed(p->decomposed.get());
  p->integrator = integrator_registry().get(c.time.integrator)(*p->op);
  // The adaptive step's default Δt_max needs the exact limit (Lanczos): computed here, at the same
  // point on every rank, on the whole model where every rank holds it (no message), else on the
  // pieces — the same bits as the serial run's configure() computes.
  if (p->decomposed && c.time.integrator == "adaptive" && !c.adaptive.dt_max && std::isfinite(p->dt_stable))
    p->exact_limit();
  p->dt_exact_configured = p->dt_exact;
  p->integrator->configure(c, p->dt_exact);
  // A step-size controller starts from its own initial step when given, else from the time.dt rule.
  if (const auto dt_initial = p->integrator->initial_dt()) p->dt = *dt_initial;
  p->steps_for_end = steps_to_reach(c.time.end, p->dt);
  p->steps_expected = std::min(p->steps_for_end, p->max_steps);

  // A fixed explicit step has no room for the indenter's stiffness 2K·h, which grows with depth:
  // the header says how deep it may go, and the loop warns once if a node gets deeper
  // (forces/indenter.hpp). A step above eq. 2.5 (dt: exact, or a fixed dt) is judged against the
  // exact limit, computed here for a fixed dt.
  p->indenter_watch = !p->model.indenters.empty() && p->integrator->explicit_step();
  if (p->indenter_watch && p->dt > p->dt_stable) {
    const double dt_exact = p->exact_limit();
    if (dt_exact > 0.0 && std::isfinite(dt_exact)) p->omega2_exact = 4.0 / (dt_exact * dt_exact);
  }
  // run.log's depth per indenter: here, where every rank is, since on pieces it is a minimum over
  // the ranks (rank 0 alone holds no rows but its own).
  if (p->indenter_watch)
    for (const auto& ind : p->model.indenters)
      p->indenter_depths.push_back(p->decomposed ? indenter_stable_depth(p->decomposed->piece().model, ind, p->dt,
                                                                         p->omega2_exact, p->decomposed.get())
                                                 : indenter_stable_depth(p->model, ind, p->dt, p->omega2_exact));
  // After configure(): the integrator sees the same dt_exact as before this check existed.
  if (p->integrator->explicit_step() && !p->integrator->controls_step()) p->step_warnings = step_warnings(*p);
  return p;
}

}  // namespace pd
