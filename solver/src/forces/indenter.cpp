// The indenter shapes, their registry and the indenter force term (see indenter.hpp).
#include "forces/indenter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "core/exact_sum.hpp"
#include "parallel/local_model.hpp"

namespace pd {

namespace {

// Sphere: r = |y − c|, h = R − r, pushed radially out (LAMMPS fix indent sphere).
double sphere(const IndenterSettings& ind, const double c[3], const double y[3], double n[3]) {
  const double d[3] = {y[0] - c[0], y[1] - c[1], y[2] - c[2]};
  const double r = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(r < ind.radius) || r == 0.0) return 0.0;  // a node at the very centre has no direction
  for (int k = 0; k < 3; ++k) n[k] = d[k] / r;
  return ind.radius - r;
}

// Cylinder: r = distance to the axis through c, h = R − r (LAMMPS fix indent cylinder; in a 2D
// case the axis is z and the cylinder is a disk).
double cylinder(const IndenterSettings& ind, const double c[3], const double y[3], double n[3]) {
  double d[3] = {y[0] - c[0], y[1] - c[1], y[2] - c[2]};
  const double along = d[0] * ind.axis[0] + d[1] * ind.axis[1] + d[2] * ind.axis[2];
  for (int k = 0; k < 3; ++k) d[k] -= along * ind.axis[k];
  const double r = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(r < ind.radius) || r == 0.0) return 0.0;
  for (int k = 0; k < 3; ++k) n[k] = d[k] / r;
  return ind.radius - r;
}

// Plane through c with unit normal n out of the indenter: h = −(y − c)·n where negative
// (LAMMPS fix indent plane).
double plane(const IndenterSettings& ind, const double c[3], const double y[3], double n[3]) {
  const double s = (y[0] - c[0]) * ind.normal[0] + (y[1] - c[1]) * ind.normal[1] + (y[2] - c[2]) * ind.normal[2];
  if (!(s < 0.0)) return 0.0;
  for (int k = 0; k < 3; ++k) n[k] = ind.normal[k];
  return -s;
}

// Chunks of this many nodes share the stable-depth bound's work between the threads, combined in
// chunk order (the node it names is the same for any thread count); the reaction and energy are
// exact sums, the same in any order.
constexpr std::int64_t kChunk = 4096;

}  // namespace

const Registry<IndenterShape>& indenter_shape_registry() {
  static const Registry<IndenterShape> registry = [] {
    Registry<IndenterShape> r("indenter shape");
    r.add("sphere", &sphere).add("cylinder", &cylinder).add("plane", &plane);
    return r;
  }();
  return registry;
}

std::array<double, 3> indenter_position(const IndenterSettings& ind, double t) {
  return {ind.centre[0] + ind.velocity[0] * t, ind.centre[1] + ind.velocity[1] * t, ind.centre[2] + ind.velocity[2] * t};
}

IndenterStepLimit indenter_step_limit(const Model& m, double t, const Vec3Array& u, double omega2_exact,
                                      const Decomposed* dec) {
  // A ghost's row is empty (its Σ would be wrong): a decomposed run looks at its owned nodes only.
  const std::vector<std::int32_t>* owned = dec ? &dec->piece().owned_local : nullptr;
  const auto n = static_cast<std::int64_t>(owned ? owned->size() : m.nodes.size());
  std::vector<IndenterShape> shapes;
  std::vector<std::array<double, 3>> centres;
  for (const IndenterSettings& ind : m.indenters) {
    shapes.push_back(indenter_shape_registry().get(ind.shape));
    centres.push_back(indenter_position(ind, t));
  }
  // Per node: bound (a) and the diagonal 2K·h/ρ that bound (b) needs, for its tightest indenter.
  struct NodeBound {
    double gershgorin = HUGE_VAL;  // (a) √(2ρ/(Σ + K·h))
    double diagonal = 0.0;         // 2K·h/ρ [1/s²]
    std::int64_t node = -1;
    std::size_t indenter = 0;
    double depth = 0.0;
  };
  auto node_bound = [&](std::size_t q) {
    NodeBound b;
    const double y[3] = {m.nodes.x[0][q] + u[0][q], m.nodes.x[1][q] + u[1][q], m.nodes.x[2][q] + u[2][q]};
    double sum = -1.0;  // eq. 2.5's Σ_q, computed only for a node inside an indenter
    for (std::size_t k = 0; k < m.indenters.size(); ++k) {
      const IndenterSettings& ind = m.indenters[k];
      double dir[3];
      const double h = shapes[k](ind, centres[k].data(), y, dir);
      if (!(h > 0.0)) continue;
      if (sum < 0.0) sum = node_stiffness(m, q);
      const double gershgorin = std::sqrt(2.0 * m.density[q] / (sum + ind.stiffness * h));
      if (gershgorin < b.gershgorin) {
        b.gershgorin = gershgorin;
        b.node = static_cast<std::int64_t>(q);
        b.indenter = k;
        b.depth = h;
      }
      b.diagonal = std::max(b.diagonal, 2.0 * ind.stiffness * h / m.density[q]);
    }
    return b;
  };
  // The force's fixed chunks of nodes, combined in chunk order: the node named is the same for any
  // thread count.
  const std::int64_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<NodeBound> tightest(static_cast<std::size_t>(chunks));
  std::vector<double> diagonal(static_cast<std::size_t>(chunks), 0.0);
#pragma omp parallel for schedule(static)
  for (std::int64_t c = 0; c < chunks; ++c) {
    NodeBound& best = tightest[static_cast<std::size_t>(c)];
    for (std::int64_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
      const NodeBound b = node_bound(owned ? static_cast<std::size_t>((*owned)[static_cast<std::size_t>(i)]) : static_cast<std::size_t>(i));
      if (b.gershgorin < best.gershgorin) best = b;
      diagonal[static_cast<std::size_t>(c)] = std::max(diagonal[static_cast<std::size_t>(c)], b.diagonal);
    }
  }
  NodeBound best;
  double max_diagonal = 0.0;
  for (std::size_t c = 0; c < tightest.size(); ++c) {
    if (tightest[c].gershgorin < best.gershgorin) best = tightest[c];
    max_diagonal = std::max(max_diagonal, diagonal[c]);
  }
  if (dec) {
    // The serial choice over the whole body: the least bound, at the lowest global node among
    // equals (min is exact in any order); the winner's depth and indenter, the others' +∞.
    if (best.node >= 0) best.node = dec->piece().global[static_cast<std::size_t>(best.node)];
    const double least = dec->minimum(best.gershgorin);
    const bool mine = best.node >= 0 && best.gershgorin == least;
    const double node = dec->minimum(mine ? static_cast<double>(best.node) : HUGE_VAL);
    max_diagonal = -dec->minimum(-max_diagonal);
    if (!std::isfinite(node)) return IndenterStepLimit{};
    const bool winner = mine && static_cast<double>(best.node) == node;
    best.gershgorin = least;
    best.node = static_cast<std::int64_t>(node);
    best.depth = dec->minimum(winner ? best.depth : HUGE_VAL);
    best.indenter = static_cast<std::size_t>(dec->minimum(winner ? static_cast<double>(best.indenter) : HUGE_VAL));
  }
  IndenterStepLimit out;
  if (best.node < 0) return out;  // no node inside any indenter
  out.node = best.node;
  out.indenter = best.indenter;
  out.depth = best.depth;
  out.dt = best.gershgorin;
  // (b): the indenter springs add a diagonal to M⁻¹K, raising ω_max² by at most its largest entry.
  if (omega2_exact > 0.0) out.dt = std::max(out.dt, 2.0 / std::sqrt(omega2_exact + max_diagonal));
  return out;
}

double indenter_stable_depth(const Model& m, const IndenterSettings& ind, double dt, double omega2_exact,
                             const Decomposed* d) {
  // A ghost's row is empty (its Σ would be 0): a decomposed run looks at its owned nodes only.
  const std::vector<std::int32_t>* owned = d ? &d->piece().owned_local : nullptr;
  const auto n = static_cast<std::int64_t>(owned ? owned->size() : m.nodes.size());
  double depth = HUGE_VAL, lightest = HUGE_VAL;
#pragma omp parallel for schedule(static) reduction(min : depth, lightest)
  for (std::int64_t i = 0; i < n; ++i) {
    const auto q = static_cast<std::size_t>(owned ? (*owned)[static_cast<std::size_t>(i)] : i);
    depth = std::min(depth, (2.0 * m.density[q] / (dt * dt) - node_stiffness(m, q)) / ind.stiffness);  // (a)
    lightest = std::min(lightest, m.density[q]);
  }
  if (d) depth = d->minimum(depth), lightest = d->minimum(lightest);  // least of least: exact in any order
  depth = std::max(depth, 0.0);
  if (omega2_exact > 0.0)  // (b): 2K·h/ρ ≤ 4/dt² − ω_max² at every node
    depth = std::max(depth, (4.0 / (dt * dt) - omega2_exact) * lightest / (2.0 * ind.stiffness));
  return depth;
}

namespace {

// f_i += K h_i² n_i over the nodes listed (all of them when `nodes` is null), and each indenter's
// force Σ V_i K h_i² n_i and the potential Σ V_i K h_i³/3 as exact sums (core/exact_sum.hpp):
// sums[3k + d] indenter k's force component d, sums[3K] the potential of all indenters. Threads
// sum their nodes apart and merge: exact, so the bits do not depend on the thread count.
std::vector<ExactSum> indenter_sums(const Model& m, double t, const Vec3Array& u, Vec3Array& f,
                                    const std::vector<std::int32_t>* nodes) {
  const auto K = m.indenters.size();
  std::vector<ExactSum> sums(3 * K + 1);
  const auto n = static_cast<std::int64_t>(nodes ? nodes->size() : m.nodes.size());
  for (std::size_t k = 0; k < K; ++k) {
    const IndenterSettings& ind = m.indenters[k];
    const IndenterShape shape = indenter_shape_registry().get(ind.shape);
    const std::array<double, 3> c = indenter_position(ind, t);
#pragma omp parallel
    {
      ExactSum mine[4];  // this thread's force components and potential
#pragma omp for schedule(static)
      for (std::int64_t e = 0; e < n; ++e) {
        const auto q = nodes ? static_cast<std::size_t>((*nodes)[static_cast<std::size_t>(e)]) : static_cast<std::size_t>(e);
        const double y[3] = {m.nodes.x[0][q] + u[0][q], m.nodes.x[1][q] + u[1][q], m.nodes.x[2][q] + u[2][q]};
        double dir[3];
        const double h = shape(ind, c.data(), y, dir);
        if (!(h > 0.0)) continue;
        const double magnitude = ind.stiffness * h * h;  // force density [N/m³]
        const double vol = m.nodes.volume[q];
        for (std::size_t d = 0; d < 3; ++d) {
          f[d][q] += magnitude * dir[d];
          mine[d].add(vol * magnitude * dir[d]);
        }
        mine[3].add(vol * ind.stiffness * h * h * h / 3.0);
      }
#pragma omp critical(pd_indenter_sums)
      {
        for (std::size_t d = 0; d < 3; ++d) sums[3 * k + d].add(mine[d]);
        sums[3 * K].add(mine[3]);
      }
    }
  }
  return sums;
}

double indenter_results(const std::vector<ExactSum>& sums, std::vector<std::array<double, 3>>& force_on_body) {
  const std::size_t K = (sums.size() - 1) / 3;
  force_on_body.assign(K, {0.0, 0.0, 0.0});
  for (std::size_t k = 0; k < K; ++k)
    for (std::size_t d = 0; d < 3; ++d) force_on_body[k][d] = sums[3 * k + d].value();
  return sums[3 * K].value();
}

}  // namespace

double IndenterForce::AddMult(double t, const Vec3Array& u, Vec3Array& f,
                              std::vector<std::array<double, 3>>& force_on_body) const {
  return indenter_results(indenter_sums(model_, t, u, f, nullptr), force_on_body);
}

double IndenterForce::AddMult(double t, const Vec3Array& u, Vec3Array& f,
                              std::vector<std::array<double, 3>>& force_on_body, const Decomposed& dec) const {
  // The owned nodes' exact sums, then every rank's added exactly (one MPI_Allreduce): the serial bits.
  std::vector<ExactSum> sums = indenter_sums(model_, t, u, f, &dec.piece().owned_local);
  dec.reduce(sums.data(), static_cast<int>(sums.size()));
  return indenter_results(sums, force_on_body);
}

}  // namespace pd

namespace pd {

void IndenterForce::AddJacobianProduct(double t, const Vec3Array& u, const Vec3Array& x, Vec3Array& y) const {
  const Model& m = model_;
  const auto n = static_cast<std::int64_t>(m.nodes.size());
  for (const IndenterSettings& ind : m.indenters) {
    const IndenterShape shape = indenter_shape_registry().get(ind.shape);
    const std::array<double, 3> c = indenter_position(ind, t);
    const bool curved = ind.shape != "plane", along_axis = ind.shape == "cylinder";
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) {
      const auto q = static_cast<std::size_t>(i);
      const double yq[3] = {m.nodes.x[0][q] + u[0][q], m.nodes.x[1][q] + u[1][q], m.nodes.x[2][q] + u[2][q]};
      double dir[3];
      const double h = shape(ind, c.data(), yq, dir);
      if (!(h > 0.0)) continue;
      // f = K h² n with h = R − r (sphere, cylinder) or the depth below the plane, so δh = −n·δy and
      // δn = P δy / r with P the projection off n (and off the axis for a cylinder); a plane's n is fixed:
      //   δf = −2K h (n·δy) n + K h²/r · P δy
      const double dy[3] = {x[0][q], x[1][q], x[2][q]};
      const double along = dir[0] * dy[0] + dir[1] * dy[1] + dir[2] * dy[2];
      double out[3];
      for (int d = 0; d < 3; ++d) out[d] = -2.0 * ind.stiffness * h * along * dir[d];
      if (curved) {
        const double r = ind.radius - h;
        const double axial = along_axis ? ind.axis[0] * dy[0] + ind.axis[1] * dy[1] + ind.axis[2] * dy[2] : 0.0;
        for (int d = 0; d < 3; ++d) {
          const double projected = dy[d] - along * dir[d] - (along_axis ? axial * ind.axis[static_cast<std::size_t>(d)] : 0.0);
          out[d] += ind.stiffness * h * h / r * projected;
        }
      }
      for (std::size_t d = 0; d < 3; ++d) y[d][q] += out[d];
    }
  }
}

void IndenterForce::AddTangentDiagonal(double t, const Vec3Array& u, std::size_t q, double block[9]) const {
  const Model& m = model_;
  const double yq[3] = {m.nodes.x[0][q] + u[0][q], m.nodes.x[1][q] + u[1][q], m.nodes.x[2][q] + u[2][q]};
  for (const IndenterSettings& ind : m.indenters) {
    const std::array<double, 3> c = indenter_position(ind, t);
    double n[3];
    const double h = indenter_shape_registry().get(ind.shape)(ind, c.data(), yq, n);
    if (!(h > 0.0)) continue;
    // The matrix of AddJacobianProduct: −2K h n nᵀ + K h²/r·P (P = I − n nᵀ [− a aᵀ for a cylinder]).
    const bool curved = ind.shape != "plane", cylinder = ind.shape == "cylinder";
    const double turn = curved ? ind.stiffness * h * h / (ind.radius - h) : 0.0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        double projection = (a == b ? 1.0 : 0.0) - n[a] * n[b];
        if (cylinder) projection -= ind.axis[static_cast<std::size_t>(a)] * ind.axis[static_cast<std::size_t>(b)];
        block[3 * a + b] += -2.0 * ind.stiffness * h * n[a] * n[b] + turn * projection;
      }
  }
}

namespace {

// The indenters as a term of the operator (forces/force_term.hpp).
class IndenterTerm : public ForceTerm {
 public:
  explicit IndenterTerm(const Model& model) : model_(model) {}
  void add_force(State& s, double t) const override {
    add_energy(s, "indenters",
               decomposed_ ? IndenterForce(model_).AddMult(t, s.u, s.f, s.indenter_force, *decomposed_)
                           : IndenterForce(model_).AddMult(t, s.u, s.f, s.indenter_force));
  }
  // A moving indenter works on the body at the rate (force on the body)·(indenter velocity): the
  // contact potential depends on y − c(t), so d(KE + potential)/dt = F·ċ.
  void add_power(const State& s, double, double& p) const override {
    for (std::size_t k = 0; k < model_.indenters.size() && k < s.indenter_force.size(); ++k)
      for (std::size_t d = 0; d < 3; ++d) p += s.indenter_force[k][d] * model_.indenters[k].velocity[d];
  }
  void add_jacobian_product(const State& s, double t, const Vec3Array& x, Vec3Array& y) const override {
    IndenterForce(model_).AddJacobianProduct(t, s.u, x, y);
  }
  bool add_tangent_diagonal(const State& s, double t, std::size_t i, double block[9]) const override {
    IndenterForce(model_).AddTangentDiagonal(t, s.u, i, block);
    return true;
  }
  std::vector<std::string> work_plan() const override {
    std::vector<std::string> lines;
    for (const auto& ind : model_.indenters) {
      char radius[64] = "", rest[192];
      if (ind.shape != "plane") std::snprintf(radius, sizeof radius, ", R %.4g m", ind.radius);
      std::snprintf(rest, sizeof rest, ", K %.4g N/m⁵, velocity (%.4g, %.4g, %.4g) m/s)", ind.stiffness,
                    ind.velocity[0], ind.velocity[1], ind.velocity[2]);
      lines.push_back("work: indenter '" + ind.name + "' (" + ind.shape + radius + rest);
    }
    return lines;
  }

 private:
  const Model& model_;
};

}  // namespace

std::unique_ptr<ForceTerm> make_indenter_term(const Model& model) {
  if (model.indenters.empty()) return nullptr;
  return std::make_unique<IndenterTerm>(model);
}

}  // namespace pd
