// Rigid indenters (LAMMPS fix indent): a sphere, a cylinder (a disk in 2D) or a plane moving at a
// prescribed velocity pushes every node inside it out along the surface normal with the force
// density K·h², h the depth of the node below the indenter surface (LAMMPS: F(r) = −K(r − R)²
// for r < R). In a PERI model LAMMPS's f is a force density, so K is in N/m⁵ here too.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/case.hpp"
#include "core/model.hpp"
#include "core/registry.hpp"

namespace pd {

// Depth h ≥ 0 of point y inside the indenter (0 outside) and the unit push direction n.
// `centre` is where the indenter is now (centre at t = 0 + velocity·t).
using IndenterShape = double (*)(const IndenterSettings& ind, const double centre[3], const double y[3], double n[3]);
const Registry<IndenterShape>& indenter_shape_registry();

// Where an indenter's centre (or plane point) is at time t.
std::array<double, 3> indenter_position(const IndenterSettings& ind, double t);

// The indenter in the stable step. A node h deep is pushed with K·h², so its stiffness along the
// push is d(K h²)/dh = 2K·h per unit volume [N/m⁴]: it adds to the sum of thesis eq. 2.5
// (node_stiffness), and the node's stable step √(2ρ/(Σ + 2K·h)) shrinks as the indenter goes in.
struct IndenterStepLimit {
  double dt = HUGE_VAL;      // min over nodes inside an indenter of √(2ρ_i / (Σ_i + 2K·h_i)) [s]
  std::int64_t node = -1;    // where (the lowest index if several), −1 if no node is inside
  std::size_t indenter = 0;  // which indenter
  double depth = 0.0;        // h of that node [m]
};
IndenterStepLimit indenter_step_limit(const Model& model, double t, const Vec3Array& u);

// The depth beyond which a step dt is no longer stable for indenter `ind` at the stiffest node of
// the body (the largest Σ_i/ρ_i): (2ρ_i/dt² − Σ_i)/(2K), minimised over nodes, ≥ 0. A lower bound:
// nodes at a surface have fewer bonds and tolerate more.
double indenter_stable_depth(const Model& model, const IndenterSettings& ind, double dt);

class IndenterForce {
 public:
  explicit IndenterForce(const Model& model) : model_(model) {}
  // f_i += K·h_i²·n_i for every node inside every indenter. force_on_body[k] = Σ_i V_i·K h_i² n_i
  // [N], the force indenter k exerts on the body (its reaction is the negative), summed in fixed
  // chunks of nodes so that it does not depend on the thread count. Returns the potential
  // Σ_k Σ_i V_i·K h_i³/3 [J] (−d/dh of it is the force).
  double AddMult(double t, const Vec3Array& u, Vec3Array& f, std::vector<std::array<double, 3>>& force_on_body) const;

 private:
  const Model& model_;
};

}  // namespace pd
