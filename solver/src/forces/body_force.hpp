// The body-force term: a prescribed force density b(t) on the nodes of a set (thesis eq. 2.1, b_i^n).
#pragma once
#include "core/model.hpp"
#include "core/state.hpp"
#include "forces/force_term.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

class BodyForceTerm {
 public:
  explicit BodyForceTerm(const Model& model) : model_(model) {}
  // f += b(t) on every node of every body-force condition. Accumulates; never clears f.
  void AddMult(double t, Vec3Array& f) const;
  // Σ_i V_i b_i(t)·v_i [W]: one exact sum per condition, each over its nodes and continuing the
  // last, so the same bits serially (d == null) and on a decomposed run (the model a rank's piece,
  // whose conditions hold its owned nodes). Collective on a decomposed run.
  double power(double t, const Vec3Array& v, const Decomposed* d = nullptr) const;

 private:
  const Model& model_;
};

}  // namespace pd
