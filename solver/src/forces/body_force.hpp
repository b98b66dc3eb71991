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
  // Σ_i V_i b_i(t)·v_i [W], summed condition by condition, each over its nodes in node order.
  double power(double t, const Vec3Array& v) const;
  // The same on a decomposed run (the model a rank's piece, whose conditions hold its owned nodes):
  // one exact sum per condition, each continuing the last (parallel/decomposed.hpp), so the
  // serial run's exact sums: the same bits on every rank. Collective.
  double power(double t, const Vec3Array& v, const Decomposed& d) const;

 private:
  const Model& model_;
};

}  // namespace pd
