// One generalized-α step: predictor, Newton on the effective tangent, the local error estimate,
// breaking, the step proposal (see implicit.hpp for the scheme and its references).
#include "integrators/implicit.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "control/zohdi.hpp"
#include "core/error.hpp"
#include "integrators/messages.hpp"
#include "integrators/newton_krylov.hpp"
#include "parallel/local_model.hpp"

namespace pd {

GeneralizedAlpha GeneralizedAlpha::of(double rho_infinity) {
  // Chung & Hulbert (1993) eqs. 25 (α_m, α_f from ρ∞), 17 (γ: second order), 20 (β: unconditional
  // stability with the most high-frequency dissipation for the given ρ∞).
  GeneralizedAlpha g{};
  g.alpha_m = (2.0 * rho_infinity - 1.0) / (rho_infinity + 1.0);
  g.alpha_f = rho_infinity / (rho_infinity + 1.0);
  g.gamma = 0.5 - g.alpha_m + g.alpha_f;
  const double shift = 1.0 - g.alpha_m + g.alpha_f;
  g.beta = 0.25 * shift * shift;
  return g;
}

void Implicit::configure(const Case& c, double) {
  settings_ = c.implicit;
  ga_ = GeneralizedAlpha::of(settings_.rho_infinity);
  const double dt_sa = op_.stable_time_step();
  const double scale = std::isfinite(dt_sa) && dt_sa > 0.0 ? dt_sa : c.time.end;
  dt_max_ = settings_.dt_max.value_or(c.time.end / 10.0);
  dt_min_ = settings_.dt_min.value_or(std::min(1e-6 * scale, dt_max_));
  // direct or cg, and why (for describe()): quasi_static's rule, over this scheme's dofs (z too in 2D).
  linear_.choose(op_, c, "implicit", settings_.linear_solver, 3);
  if (dt_min_ > dt_max_)
    throw Error(c.file.string() + ": implicit.dt_min = " + message_number(dt_min_) + " s is above dt_max = " +
                message_number(dt_max_) + " s; lower implicit.dt_min or raise implicit.dt_max");
}

std::string Implicit::keep_linear_solver(const std::string& recorded) {
  const std::string here = linear_solver();
  if (recorded == here) return {};
  if (std::string why = why_not_linear_solver(op_, recorded); !why.empty()) return why;
  linear_.keep_recorded(recorded != "direct", here);
  return {};
}

bool Implicit::solve_krylov(const State& s, double t1, double h, double floor) {
  const double c = mass_coefficient(h);
  // A law with neither form of diagonal block: 1×1 blocks of 0, the mass term alone preconditions.
  linear_.stiffness_blocks(op_, s, t1, dofs_, 0.0);
  // K_eff's blocks: + c m on the diagonal (a node's dofs share its mass).
  linear_.each_block_diagonal([&](double& entry, std::size_t q) { entry += c * mass_[q]; });
  linear_.build_block_jacobi();
  PcgSettings settings;
  settings.relative_tol = kCgTolerance;
  settings.absolute_tol = floor;
  settings.max_iterations = settings_.cg_max_iterations;
  std::vector<double>& diagonal = linear_.cg_diagonal();
  diagonal.resize(dofs_.size());
  for (std::size_t q = 0; q < dofs_.size(); ++q) diagonal[q] = c * mass_[q];  // K_eff = K + c M
  const PcgResult result = linear_.solve_cg(op_, s, t1, dofs_, sums_, r_, correction_, settings);
  report_.force_evaluations += result.iterations + 1;  // a matvec costs about one force evaluation
  return result.converged() || result.status == PcgResult::kIndefinite || result.residual < result.initial_residual;
}

std::string Implicit::linear_algebra_summary() const {
  if (!linear_.uses_cg()) return {};  // the direct path's done: line stays as it was
  return std::to_string(linear_.cg_solves()) + " CG solves with " + std::to_string(linear_.cg_iterations()) +
         " iterations (J·x products)";
}

void Implicit::resume(const State& state) {
  for (std::size_t q = 0; q < dofs_.size(); ++q) {
    const auto i = static_cast<std::size_t>(dofs_.node[q]);
    const std::size_t d = dofs_.component[q];
    a_[d][i] = state.f[d][i] / op_.density()[i] - op_.damping() * state.v[d][i];
  }
  linear_.forget_factor();
  proposal_ = 0.0;
}

void Implicit::initialize(State& state, double t) {
  op_.start(state, t);
  const std::size_t n = state.size();
  // Every component that is not prescribed, z too in 2D: Verlet moves a 2D membrane out of plane
  // (cases/drum), and so must this scheme. K has no z stiffness in a flat unstressed sheet, but
  // K_eff has the mass; z stays exactly 0 where nothing moves it (a zero right-hand side).
  dofs_ = op_.free_dofs(3);
  sums_.setup(op_.decomposed(), dofs_);
  for (auto& terms : terms_) terms.assign(dofs_.size(), 0.0);
  if (linear_.uses_cg()) linear_.size_cg(n);
  const auto& volume = op_.model().nodes.volume;
  const auto& rho = op_.density();
  mass_.resize(dofs_.size());
  a_ = make_vec3(n);
  // a_0 from the equation of motion, ρ a = f − α ρ v: with it the ρ∞ = 1 scheme is exactly the
  // trapezoidal rule (implicit.hpp).
  for (std::size_t q = 0; q < dofs_.size(); ++q) {
    const auto i = static_cast<std::size_t>(dofs_.node[q]);
    const std::size_t d = dofs_.component[q];
    mass_[q] = rho[i] * volume[i];
    a_[d][i] = state.f[d][i] / rho[i] - op_.damping() * state.v[d][i];
  }
  trial_ = State(n);
  r_.assign(dofs_.size(), 0.0);
  a_new_.assign(dofs_.size(), 0.0);
  v_new_.assign(dofs_.size(), 0.0);
  linear_.forget_factor();
  linear_.set_factorisations(0);
  proposal_ = 0.0;
  last_error_ = 0.0;
  report_ = StepReport{};
}

double Implicit::mass_coefficient(double h) const {
  return (1.0 - ga_.alpha_m) / ((1.0 - ga_.alpha_f) * ga_.beta * h * h) + op_.damping() * ga_.gamma / (ga_.beta * h);
}

bool Implicit::factorize_at(const State& s, double t1, double h, bool definite) {
  FactorPoint at;
  at.t = t1, at.dt = h, at.definite = definite;
  return linear_.factorize(op_, s, dofs_, at, "implicit", [&](SparseMatrix& K) {
    // K_eff = K + m·c on the diagonal (implicit.hpp).
    const double c = mass_coefficient(h);
    for (std::int64_t r = 0; r < K.rows; ++r)
      for (std::int64_t q = K.row_start[static_cast<std::size_t>(r)]; q < K.row_start[static_cast<std::size_t>(r) + 1]; ++q)
        if (K.column[static_cast<std::size_t>(q)] == r) K.value[static_cast<std::size_t>(q)] += c * mass_[static_cast<std::size_t>(r)];
  });
}

double Implicit::residual(const State& start, const State& s, double h, double& scale) {
  const auto& volume = op_.model().nodes.volume;
  const double alpha = op_.damping(), am = ga_.alpha_m, af = ga_.alpha_f, beta = ga_.beta, gamma = ga_.gamma;
  // Σ r², Σ inertia², Σ force², exactly (over the ranks: parallel/dof_sums.hpp): the same for any
  // thread and rank count.
  for (std::size_t q = 0; q < dofs_.size(); ++q) {
    const auto i = static_cast<std::size_t>(dofs_.node[q]);
    const std::size_t d = dofs_.component[q];
    const double an = a_[d][i], vn = start.v[d][i];
    const double u_tilde = start.u[d][i] + h * vn + h * h * (0.5 - beta) * an;
    const double a1 = (s.u[d][i] - u_tilde) / (beta * h * h);
    const double v1 = vn + h * (1.0 - gamma) * an + gamma * h * a1;
    const double inertia = mass_[q] * ((1.0 - am) * a1 + am * an + alpha * ((1.0 - af) * v1 + af * vn));
    const double force = volume[i] * ((1.0 - af) * s.f[d][i] + af * start.f[d][i]);
    a_new_[q] = a1;
    v_new_[q] = v1;
    r_[q] = inertia - force;
    terms_[0][q] = r_[q] * r_[q];
    terms_[1][q] = inertia * inertia;
    terms_[2][q] = force * force;
  }
  const std::vector<double> sums = sums_.sums({&terms_[0], &terms_[1], &terms_[2]});
  scale = std::sqrt(sums[1]) + std::sqrt(sums[2]);
  return std::sqrt(sums[0]);
}

bool Implicit::solve_step(const State& start, State& s, double t1, double h, int& iterations, double& omega) {
  op_.evaluate(s, t1);
  ++report_.force_evaluations;
  double previous = HUGE_VAL;
  bool fresh = false;  // a factorisation made in this step
  omega = HUGE_VAL;
  for (int k = 1; k <= settings_.max_iterations; ++k) {
    double scale = 0.0;
    const double res = residual(start, s, h, scale);
    if (!std::isfinite(res)) return false;
    // Converged: two of the three signs — the last correction below newton_tol, the residual below
    // its tolerance, the residual no longer falling — or no longer falling with a tangent made in
    // this step after two corrections. A residual that a fresh tangent cannot lower is at the
    // round-off floor of the stretches (about 1e-16/strain of the bond forces): there the corrections
    // are noise, and at a small amplitude, a short step or in a pre-stressed body at rest (the drum
    // before it moves: bond forces of ε0 that cancel, a motion of nearly nothing) neither the
    // correction relative to the step's motion nor the residual relative to the net force gets below
    // its tolerance.
    const bool small_correction = omega <= settings_.newton_tol, small_residual = res <= settings_.residual_tol * scale,
               stalled = res >= 0.5 * previous;
    if (k > 1 && (small_correction ? small_residual || stalled : stalled && (small_residual || (fresh && k >= 3))))
      return true;
    if (res == 0.0) return omega = 0.0, true;  // the predictor is the solution (nothing moves or loads)
    // Reuse the factorisation while Δt is the one it was made for and it keeps the residual falling
    // fast; else assemble and factorise at the current iterate — once per step: a tangent made in
    // this step that no longer cuts the residual 4× is at the round-off floor, or the step is too
    // long for the nonlinearity (then the step is cut).
    if (linear_.uses_cg()) {
      fresh = true;  // every iterate's own tangent (full Newton)
    } else if (!linear_.have_factor() || linear_.factor_point().dt != h || (res > 0.25 * previous && !fresh)) {
      fresh = true;
      // The definite variant (compressed bonds without their negative lateral stiffness) when the
      // full tangent plus the mass is not positive definite (large Δt under compression): modified
      // Newton, the residual still decides convergence.
      if (!factorize_at(s, t1, h, false) && !factorize_at(s, t1, h, true)) return false;
    }
    previous = res;
    const double to_dofs = -1.0 / (1.0 - ga_.alpha_f);  // K_eff Δu = −r/(1 − α_f)
    for (double& value : r_) value *= to_dofs;
    if (linear_.uses_cg()) {
      if (!solve_krylov(s, t1, h, -0.5 * to_dofs * settings_.residual_tol * scale)) return false;
    } else {
      linear_.solve(r_, correction_);
    }
    // Backtracking: the full correction unless it raises the residual (then ½, ¼, … up to 1/32).
    // The trial's force evaluation is the next iteration's.
    double step = 1.0;
    for (int halving = 0;; ++halving) {
      trial_ = s;
      for (std::size_t q = 0; q < dofs_.size(); ++q) {
        const auto i = static_cast<std::size_t>(dofs_.node[q]);
        trial_.u[dofs_.component[q]][i] = s.u[dofs_.component[q]][i] + step * correction_[q];
      }
      op_.evaluate(trial_, t1);
      ++report_.force_evaluations;
      double trial_scale = 0.0;
      if (halving == 5 || residual(start, trial_, h, trial_scale) < res) break;
      step *= 0.5;
    }
    std::swap(s, trial_);
    for (std::size_t q = 0; q < dofs_.size(); ++q) {
      const auto i = static_cast<std::size_t>(dofs_.node[q]);
      const double du = step * correction_[q], motion = s.u[dofs_.component[q]][i] - start.u[dofs_.component[q]][i];
      terms_[0][q] = du * du;
      terms_[1][q] = motion * motion;
    }
    const std::vector<double> norms = sums_.sums({&terms_[0], &terms_[1]});
    const double dc = norms[0], dm = norms[1];
    omega = dm > 0.0 ? std::sqrt(dc / dm) : 0.0;  // eq. 2.6 for Newton
    iterations = k;
    if (!std::isfinite(omega)) return false;
  }
  double scale = 0.0;
  const double res = residual(start, s, h, scale);
  const bool stalled = res >= 0.5 * previous;
  return (omega <= settings_.newton_tol || stalled) && (res <= settings_.residual_tol * scale || stalled);
}

void Implicit::step(State& state, double& t, double& dt) {
  report_ = StepReport{};
  report_.force_evaluations = 0;
  const bool shortened = proposal_ > 0.0 && dt < proposal_;  // the caller cut it to land on a time
  const auto& rho = op_.density();
  double h = std::min(dt, dt_max_);
  int total_iterations = 0;
  for (;;) {
    const double t1 = t + h;
    State s = state;
    // Predictor: constant acceleration, u* = u_n + Δt v_n + Δt²/2 a_n (no force evaluation).
    for (std::size_t q = 0; q < dofs_.size(); ++q) {
      const auto i = static_cast<std::size_t>(dofs_.node[q]);
      const std::size_t d = dofs_.component[q];
      s.u[d][i] = state.u[d][i] + h * state.v[d][i] + 0.5 * h * h * a_[d][i];
    }
    op_.advance_prescribed_motion(state.u, s.u, s.v, t, t1, h, true);
    int iterations = 0;
    double omega = 0.0;
    const bool converged = solve_step(state, s, t1, h, iterations, omega);
    total_iterations += iterations;
    double eta = 0.0;
    if (converged) {
      // The local error estimate (implicit.hpp), against the step's motion like eq. 2.6.
      const double c = ga_.error_coefficient() * h * h;
      for (std::size_t q = 0; q < dofs_.size(); ++q) {
        const auto i = static_cast<std::size_t>(dofs_.node[q]);
        const std::size_t d = dofs_.component[q];
        const double e = c * (a_new_[q] - a_[d][i]), motion = s.u[d][i] - state.u[d][i];
        terms_[0][q] = e * e;
        terms_[1][q] = motion * motion;
      }
      const std::vector<double> norms = sums_.sums({&terms_[0], &terms_[1]});
      const double e2 = norms[0], m2 = norms[1];
      // Motions below kMotionFloor × dx per dof are not measured against themselves: a body at rest
      // (round-off noise) or the first instants of a load that starts smoothly from zero (force ∝ t²:
      // the first step's relative error is O(1) at any Δt) would otherwise be cut down to dt_min.
      const auto dof_count = op_.decomposed() ? op_.decomposed()->total(static_cast<std::int64_t>(dofs_.size()))
                                              : static_cast<std::int64_t>(dofs_.size());
      const double floor = kMotionFloor * op_.model().nodes.grid_spacing * std::sqrt(static_cast<double>(dof_count));
      const double motion = std::max(std::sqrt(m2), floor);
      eta = motion > 0.0 ? std::sqrt(e2) / motion : 0.0;
      if (eta <= settings_.tol) {
        for (std::size_t q = 0; q < dofs_.size(); ++q) {
          const auto i = static_cast<std::size_t>(dofs_.node[q]);
          const std::size_t d = dofs_.component[q];
          s.v[d][i] = v_new_[q];
          a_[d][i] = a_new_[q];
        }
        // Thesis order: accept, break, then the force with the bonds left (implicit.hpp).
        if (op_.can_break()) {
          const BreakReport broke = op_.break_bonds(s);
          if (broke.broken > 0) {
            const Vec3Array f_old = s.f;
            op_.evaluate(s, t1);
            ++report_.force_evaluations;
            for (std::size_t q = 0; q < dofs_.size(); ++q) {
              const auto i = static_cast<std::size_t>(dofs_.node[q]);
              const std::size_t d = dofs_.component[q];
              a_[d][i] += (s.f[d][i] - f_old[d][i]) / rho[i];
            }
            linear_.forget_factor();  // the tangent lost bonds
            report_.broken_now = broke.broken;
            report_.broken_energy_now = broke.energy;
          }
        }
        op_.update_work(s, t1, h);
        state = std::move(s);
        t = t1;
        dt = h;
        last_error_ = eta;
        report_.iterations = std::max(total_iterations, 1);
        // The proposal: the smaller of eq. 2.8's Φ_K and the error's factor, at most 2×; a growth
        // under 25 % keeps Δt (and the factorisation made for it).
        const double by_error = eta > 0.0 ? 0.9 * std::sqrt(settings_.tol / eta) : HUGE_VAL;
        const double by_newton = zohdi_step_factor(settings_.newton_tol, omega, std::max(iterations, 1), settings_.kd, settings_.p);
        double factor = std::min({by_error, by_newton, 2.0});
        if (factor >= 0.9 && factor < 1.25) factor = 1.0;  // by_error ≥ 0.9 ⇔ η ≤ tol: Δt still fits
        double next = factor * h;
        if (shortened && report_.rejected == 0 && factor >= 1.0) next = std::max(next, std::min(proposal_, dt_max_));
        next = std::max(std::min(next, dt_max_), dt_min_);
        report_.next_dt = next;
        proposal_ = next;
        return;
      }
    }
    // Rejected: Newton did not converge (Δt/2), or the error estimate is above tol (its factor).
    if (h <= dt_min_ * (1.0 + 1e-12)) {
      report_.iterations = std::max(total_iterations, 1);
      throw StepFailed(
          converged ? "the implicit step's local error estimate " + message_number(eta) + " stays above implicit.tol = " +
                          message_number(settings_.tol) + " at dt_min = " + message_number(dt_min_) + " s (t = " +
                          message_number(t) + " s): raise implicit.tol or lower implicit.dt_min"
                    : "Newton did not converge in the implicit step at dt_min = " + message_number(dt_min_) + " s (t = " +
                          message_number(t) + " s, " + std::to_string(report_.rejected + 1) + " attempts, last correction ω = " +
                          message_number(omega) + "): raise implicit.max_iterations, or use time.integrator: verlet");
    }
    ++report_.rejected;
    if (!converged) linear_.forget_factor();  // a failed Newton may have left a useless factor
    h = std::max(converged ? h * std::max(0.2, 0.9 * std::sqrt(settings_.tol / eta)) : 0.5 * h, dt_min_);
  }
}

std::vector<char> Implicit::save_state() const {
  std::vector<char> bytes = Integrator::save_state();
  auto put = [&bytes](const auto& value) {
    const auto* p = reinterpret_cast<const char*>(&value);
    bytes.insert(bytes.end(), p, p + sizeof value);
  };
  auto put_vec3 = [&bytes](const Vec3Array& a) {
    for (const auto& component : a)
      bytes.insert(bytes.end(), reinterpret_cast<const char*>(component.data()),
                   reinterpret_cast<const char*>(component.data() + component.size()));
  };
  const FactorPoint& at = linear_.factor_point();
  const std::uint8_t have = linear_.have_factor() ? 1 : 0, definite = at.definite ? 1 : 0;
  const int factorisations = linear_.factorisations();
  put(have), put(definite), put(at.t), put(at.dt), put(proposal_), put(last_error_), put(factorisations);
  // a_n is in the checkpoint's pieces (checkpointed_node_arrays): each rank writes its owned nodes'.
  if (linear_.have_factor()) put_vec3(linear_.factor_u());
  return bytes;
}

void Implicit::load_state(const std::vector<char>& bytes) {
  constexpr std::size_t fixed_part = 2 + 4 * sizeof(double) + sizeof(int);
  const Decomposed* decomposed = op_.decomposed();
  // A factor's u is the whole model's (a factor is made on one process); a decomposed run drops it.
  const std::size_t n = decomposed ? static_cast<std::size_t>(decomposed->piece().global_nodes) : op_.size();
  const std::size_t vec3 = 3 * n * sizeof(double);
  if (bytes.size() < kReportBytes + fixed_part) throw std::runtime_error("integrator state of the wrong size");
  const bool have = bytes[kReportBytes] != 0;
  if (bytes.size() != kReportBytes + fixed_part + (have ? vec3 : 0))
    throw std::runtime_error("integrator state of the wrong size");
  load_report(std::vector<char>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(kReportBytes)), 0);
  const char* at = bytes.data() + kReportBytes + 1;
  const bool definite = *at++ != 0;
  double t = 0.0, h = 0.0;
  int factorisations = 0;
  auto get = [&at](auto& value) { std::memcpy(&value, at, sizeof value), at += sizeof value; };
  auto get_vec3 = [&at, n](Vec3Array& a) {
    a = make_vec3(n);
    for (auto& component : a) std::memcpy(component.data(), at, n * sizeof(double)), at += n * sizeof(double);
  };
  get(t), get(h), get(proposal_), get(last_error_), get(factorisations);
  linear_.forget_factor();
  if (have) {
    State s(n);
    get_vec3(s.u);
    // Needs the bonds of the checkpoint (restored before load_state, run/start.cpp). A factor of a
    // run on one process is of no use to CG (a decomposed run resuming from it): dropped.
    if (!linear_.uses_cg() && !factorize_at(s, t, h, definite)) throw std::runtime_error("the saved tangent could not be factorised again");
  }
  linear_.set_factorisations(factorisations);
}

std::vector<std::string> Implicit::describe(double) const {
  return {"implicit: generalized-α (Chung & Hulbert 1993), rho_infinity " + message_number(settings_.rho_infinity) +
              " (α_m " + message_number(ga_.alpha_m) + ", α_f " + message_number(ga_.alpha_f) + ", β " +
              message_number(ga_.beta) + ", γ " + message_number(ga_.gamma) + "); local error TOL " +
              message_number(settings_.tol) + " (Zienkiewicz & Xie)",
          "implicit: Newton to correction " + message_number(settings_.newton_tol) + " and residual " +
              message_number(settings_.residual_tol) + ", Kd " + std::to_string(settings_.kd) + ", p " +
              message_number(settings_.p) +
              (linear_.uses_cg() ? "; linear solves of tangent + mass/(βΔt²) by matrix-free CG with block-Jacobi (cg, "
                       : "; tangent + mass/(βΔt²) factorised by CHOLMOD (direct, ") +
              linear_.reason() + "); steps dt_initial " +
              (settings_.dt_initial ? message_number(*settings_.dt_initial) + " s" : std::string("from time.dt")) +
              ", dt_min " + message_number(dt_min_) + " s, dt_max " + message_number(dt_max_) + " s"};
}

}  // namespace pd
