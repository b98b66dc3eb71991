// What the operator asks of a decomposed run (issue 15), without naming MPI: fill the ghosts of a
// per-node array before a sweep, and sum per-node values in an order that does not depend on the
// decomposition. parallel/mpi_decomposed implements it with MPI; a serial run has none (null), and
// parallel/node_sum.hpp then sums in node order exactly as before.
#pragma once
#include <cstdint>
#include <vector>

#include "core/nodes.hpp"

namespace pd {

class Decomposed {
 public:
  virtual ~Decomposed() = default;
  // Sets the ghost entries of a local per-node array (e.g. the displacement) to their owners'
  // values: exact copies, so a row sums the same bits as on one rank.
  virtual void update_ghosts(Vec3Array& a) const = 0;
  // start + Σ over owned local nodes of per_node[l], added one by one in global node order (the
  // serial sum's order), the same on every rank: bitwise the serial result for any rank count.
  // Entries of ghosts are ignored. start lets a serial sum that runs through several loops (over
  // components, over conditions) be continued loop by loop. A node the serial loop skips may enter
  // as +0.0: a sum that starts at +0.0 never becomes −0.0, and x + (+0.0) = x for any other x, so
  // the bits are those of skipping it. Collective: every rank calls it.
  virtual double ordered_sum(const std::vector<double>& per_node, double start = 0.0) const = 0;
  // Σ over ranks of an integer (exact, so the order does not matter). Collective.
  virtual std::int64_t total(std::int64_t local) const = 0;
  // The least of the ranks' values (exact, so the order does not matter). Collective.
  virtual double minimum(double local) const = 0;
};

}  // namespace pd
