// Per-node arrays whose ghost entries travel together in one halo exchange (issue 15): a
// displacement's three components, a scalar (LPS's P), or several at once — u with LAMMPS's
// per-node s0 (the α rule reads both of a bond's far end), LPS's P with δP (its J·v). One exchange
// sends each neighbouring rank one message of `width` doubles per ghost, node by node, instead of
// one message per array: fewer messages, and one wait (parallel/halo, parallel/row_split.hpp).
// Pointers only: the arrays must outlive the exchange and keep their size.
#pragma once
#include <stdexcept>
#include <vector>

#include "core/nodes.hpp"

namespace pd {

class NodeColumns {
 public:
  static constexpr int kMostColumns = 4;  // u and s0
  NodeColumns() = default;
  NodeColumns(Vec3Array& a) { add(a); }           // NOLINT: implicit, so update_ghosts(u) reads as before
  NodeColumns(std::vector<double>& a) { add(a); }  // NOLINT: the same for a scalar per node
  NodeColumns& add(std::vector<double>& a) {
    if (width_ == kMostColumns) throw std::logic_error("NodeColumns: more than 4 arrays in one exchange");
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

}  // namespace pd
