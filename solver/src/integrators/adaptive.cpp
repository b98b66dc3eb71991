// One adaptive step of thesis §2.2: predictor, fixed-point iterations with eqs. 2.6–2.8, retries.
#include "integrators/adaptive.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "control/zohdi.hpp"
#include "core/error.hpp"
#include "parallel/node_sum.hpp"
#include "integrators/messages.hpp"

namespace pd {

void AdaptiveStep::configure(const Case& c, double dt_exact_known) {
  settings_ = c.adaptive;
  // Default Δt_max: eq. 2.5 (docs/theory.md T12: keep Δt ≤ Δt_SA), and below the step where the
  // fixed-point iteration stops contracting, φΔtω_max < 1, i.e. Δt < Δt_exact/(2φ) (adaptive.hpp).
  // Above that limit every few steps diverge and are redone at half the step: with φ = 1 on the
  // membrane (Δt_exact/2 = 0.84 × eq. 2.5) the default eq. 2.5 cost a rejection on every other
  // step (cases/membrane/README.md). 0.9 keeps the contraction factor (φΔtω_max)² ≤ 0.81.
  // Δt_min = 1e-6·Δt_SA is far below any useful step.
  const double dt_sa = op_.stable_time_step();
  const double scale = std::isfinite(dt_sa) ? dt_sa : c.time.end;
  double dt_max = scale;
  limit_seconds_ = 0.0;
  if (!settings_.dt_max && std::isfinite(dt_sa)) {
    const auto start = std::chrono::steady_clock::now();  // Lanczos: reported in run.log
    const double dt_exact = dt_exact_known > 0.0 ? dt_exact_known : op_.exact_time_step();
    limit_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (std::isfinite(dt_exact)) dt_max = std::min(dt_max, 0.9 * dt_exact / (2.0 * settings_.phi));
  }
  dt_max_ = settings_.dt_max.value_or(dt_max);
  dt_min_ = settings_.dt_min.value_or(std::min(1e-6 * scale, dt_max_));
  // The reader checks dt_min ≤ dt_max when both are given; a default Δt_max can still fall below a
  // given dt_min, and then the first rejected attempt would end the run.
  if (dt_min_ > dt_max_)
    throw Error(c.file.string() + ": adaptive.dt_min = " + message_number(dt_min_) + " s is above the default dt_max = " +
                message_number(dt_max_) + " s (eq. 2.5 and the contraction limit of the fixed-point iteration); lower "
                "adaptive.dt_min or give adaptive.dt_max");
}

void AdaptiveStep::initialize(State& state, double t) {
  if (dt_max_ <= 0.0) {  // not configured (tests that build the integrator bare): the defaults
    Case defaults;
    defaults.time.end = 1.0;
    configure(defaults);
  }
  op_.start(state, t);
  const std::size_t n = state.size();
  trial_ = State(n);
  u_new_ = make_vec3(n);
  v_new_ = make_vec3(n);
  correction_.assign(n, 0.0);
  motion_.assign(n, 0.0);
  report_ = StepReport{};
  proposal_ = 0.0;
}

std::vector<char> AdaptiveStep::save_state() const {
  std::vector<char> bytes = Integrator::save_state();
  const std::size_t at = bytes.size();
  bytes.resize(at + sizeof proposal_);
  std::memcpy(bytes.data() + at, &proposal_, sizeof proposal_);
  return bytes;
}

void AdaptiveStep::load_state(const std::vector<char>& bytes) {
  load_report(bytes, sizeof proposal_);
  std::memcpy(&proposal_, bytes.data() + kReportBytes, sizeof proposal_);
}

void AdaptiveStep::update(const State& s, const Vec3Array& f_imp, double t, double t1, double dt) {
  const auto n = static_cast<std::int64_t>(s.size());
  const double phi = settings_.phi, alpha = op_.damping();
  const double keep = 1.0 - (1.0 - phi) * alpha * dt;  // damping weights, see adaptive.hpp
  const double divide = 1.0 / (1.0 + phi * alpha * dt);
  const double* rho = op_.density().data();
  for (std::size_t d = 0; d < 3; ++d) {
    const double* u0 = s.u[d].data();
    const double* v0 = s.v[d].data();
    const double* f0 = s.f[d].data();
    const double* f1 = f_imp[d].data();
    const std::uint8_t* fx = op_.fixed()[d].data();
    double* u = u_new_[d].data();
    double* v = v_new_[d].data();
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) {
      if (fx[i]) continue;
      v[i] = (keep * v0[i] + dt * (phi * f1[i] + (1.0 - phi) * f0[i]) / rho[i]) * divide;
      u[i] = u0[i] + dt * ((1.0 - phi) * v0[i] + phi * v[i]);  // the same θ-weight φ as v
    }
  }
  // Prescribed components follow their tables exactly as in Verlet (the same at every iterate).
  op_.advance_prescribed_motion(s.u, u_new_, v_new_, t, t1, dt, true);
}

void AdaptiveStep::step(State& state, double& t, double& dt) {
  const auto n = static_cast<std::int64_t>(state.size());
  const double tol = settings_.tol, p = settings_.p;
  const int kd = settings_.kd;
  const bool shortened = proposal_ > 0.0 && dt < proposal_;  // the caller cut it to land on a time
  report_ = StepReport{};
  report_.force_evaluations = 0;
  double h = std::min(dt, dt_max_);  // the first step (time.dt or dt_initial) too stays ≤ Δt_max
  for (;;) {
    const double t1 = t + h;
    // K = 0: the explicit predictor (f(u^n) in place of the implicit force; no evaluation).
    update(state, state.f, t, t1, h);
    double c_prev = 0.0, c_prev2 = 0.0, phi_k = 1.0;
    bool accepted = false, diverged = false;
    int k = 1;
    for (; k <= kd; ++k) {
      std::swap(trial_.u, u_new_);  // u^{n+1,K−1} → trial
      op_.evaluate(trial_, t1);
      ++report_.force_evaluations;
      update(state, trial_.f, t, t1, h);  // → u^{n+1,K}
      // Eq. 2.6, per node first and summed serially, so accept/reject decisions (and every result)
      // are the same for any thread count.
#pragma omp parallel for schedule(static)
      for (std::int64_t i = 0; i < n; ++i) {
        double dc = 0.0, dm = 0.0;
        for (std::size_t d = 0; d < 3; ++d) {
          const double a = u_new_[d][static_cast<std::size_t>(i)];
          const double b = trial_.u[d][static_cast<std::size_t>(i)] - a;
          const double m = state.u[d][static_cast<std::size_t>(i)] - a;
          dc += b * b;
          dm += m * m;
        }
        correction_[static_cast<std::size_t>(i)] = std::sqrt(dc);
        motion_[static_cast<std::size_t>(i)] = std::sqrt(dm);
      }
      // Two exact sums (each independent of the other), through the one reduction over nodes: on
      // a decomposed run the serial sums' bits on every rank (ghosts left out), so every rank
      // accepts or rejects alike; both in one MPI_Allreduce.
      const std::array<double, 2> cm = sums_over_nodes<2>(op_.decomposed(), correction_.size(), [&](std::size_t i) {
        return std::array<double, 2>{correction_[i], motion_[i]};
      });
      const double c = cm[0], m = cm[1];
      if (!std::isfinite(c) || !std::isfinite(m)) {
        phi_k = 0.01;
        diverged = true;
        break;
      }
      // Nothing moves (a body at rest): the step is exact, ω_K = 0.
      const double omega = m > 0.0 ? c / m : 0.0;
      // Eq. 2.8 with ω_0 = 1 (see adaptive.hpp); ω_K = 0 proposes an unbounded step, capped below.
      phi_k = zohdi_step_factor(tol, omega, k, kd, p);
      if (omega <= tol) {  // eq. 2.7: Z_K ≤ 1
        accepted = true;
        break;
      }
      if (k >= 3 && c > c_prev && c_prev > c_prev2) {
        const double growth = c / c_prev;
        phi_k = std::min(0.5, std::pow(std::pow(tol, 1.0 / kd) / growth, 1.0 / p));
        diverged = true;
        break;
      }
      c_prev2 = c_prev;
      c_prev = c;
    }
    if (accepted) {
      report_.iterations = k;
      std::swap(state.u, u_new_);
      std::swap(state.v, v_new_);
      // Bonds break on the accepted state only, then the force there for the next step.
      const BreakReport broke = op_.break_bonds_and_evaluate(state, t1);
      report_.broken_now += broke.broken;
      report_.broken_energy_now += broke.energy;
      ++report_.force_evaluations;
      op_.update_work(state, t1, h);
      t = t1;
      dt = h;
      double next = std::min(phi_k * h, dt_max_);
      if (shortened && report_.rejected == 0 && phi_k >= 1.0) next = std::max(next, std::min(proposal_, dt_max_));
      next = std::max(next, dt_min_);
      report_.next_dt = next;
      proposal_ = next;
      return;
    }
    // Rejected (Z > 1 at K_d, or diverging): redo from t with a smaller step.
    if (h <= dt_min_ * (1.0 + 1e-12)) {
      report_.iterations = std::min(k, kd);
      throw StepFailed("the adaptive step did not converge at dt_min = " + message_number(dt_min_) + " s (t = " + message_number(t) +
                       " s, " + std::to_string(report_.rejected + 1) + " attempts" +
                       (diverged ? ", the fixed-point iteration diverged" : "") +
                       "); the motion is too violent for TOL = " + message_number(tol) +
                       " at this dt_min: raise adaptive.tol, lower adaptive.dt_min, or look for a load or "
                       "contact that makes the state jump");
    }
    ++report_.rejected;
    h = std::max(std::min(phi_k, 0.9) * h, dt_min_);
  }
}

// ---- What the run asks (integrator.hpp): its run.log line
std::vector<std::string> AdaptiveStep::describe(double dt_exact) const {
  const auto text = [](const char* fmt, double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, fmt, value);
    return std::string(buffer);
  };
  return {"adaptive (thesis §2.2): TOL " + text("%g", settings_.tol) + ", Kd " + std::to_string(settings_.kd) +
          ", p " + text("%g", settings_.p) + ", phi " + text("%g", settings_.phi) + ", dt_min " + text("%.6g", dt_min_) +
          " s, dt_max " + text("%.6g", dt_max_) + " s" +
          (settings_.dt_max ? std::string()
           : dt_exact > 0.0
               ? std::string(" (default: eq. 2.5 or 0.9 × the contraction limit, from the exact limit above)")
               : " (default: eq. 2.5 or 0.9 × the contraction limit, eigenvalue estimate " + text("%.3f", limit_seconds_) +
                     " s)")};
}

}  // namespace pd
