// Per-node arrays whose ghost entries travel together in one halo exchange (issue 15): a
// displacement's three components, a scalar (LPS's P), or several at once — u with a law's declared
// per-node history (core/state_arrays.hpp: LAMMPS's s0, which the α rule reads at a bond's far end),
// LPS's P with δP (its J·v). One exchange
// sends each neighbouring rank one message of `width` doubles per ghost, node by node, instead of
// one message per array: fewer messages, and one wait (parallel/halo, parallel/row_split.hpp).
// Pointers only: the arrays must outlive the exchange and keep their size.
#pragma once
#include <stdexcept>
#include <string>
#include <vector>

#include "core/nodes.hpp"
#include "core/state_arrays.hpp"

namespace pd {

class NodeColumns {
 public:
  // u and up to five components of declared history: a fixed array, so a NodeColumns is copied into
  // an exchange's handle without allocating.
  static constexpr int kMostColumns = 8;
  NodeColumns() = default;
  NodeColumns(Vec3Array& a) { add(a); }           // NOLINT: implicit, so update_ghosts(u) reads as before
  NodeColumns(std::vector<double>& a) { add(a); }  // NOLINT: the same for a scalar per node
  NodeColumns& add(std::vector<double>& a) {
    if (width_ == kMostColumns) throw std::logic_error("NodeColumns: more than " + std::to_string(kMostColumns) + " arrays in one exchange");
    column_[width_++] = a.data();
    return *this;
  }
  NodeColumns& add(Vec3Array& a) {
    for (auto& c : a) add(c);
    return *this;
  }
  int width() const { return width_; }
  double* operator[](int c) const { return column_[c]; }

 private:
  double* column_[kMostColumns] = {};
  int width_ = 0;
};

// `columns` and every component of the declared per-node arrays with `halo`, in declaration order:
// what a breaking pass reads of a ghost besides u (operator/force_operator).
inline NodeColumns& add_halo_state(NodeColumns& columns, StateArrays& arrays) {
  for (StateArray& a : arrays.all()) {
    const StateDeclaration& d = a.declaration;
    if (!d.halo || d.extent != StateExtent::per_node) continue;
    if (d.components != 1)
      throw std::logic_error("declared state '" + d.name + "': only one component per node travels with the ghosts");
    columns.add(a.values);
  }
  return columns;
}

}  // namespace pd
