// A material with history that exists only in the tests (tests/materials/test_declared_state.cpp,
// tests/mpi/test_decomposed_overlap.cpp): PMB whose bonds remember their largest stretch (a history
// per bond, as a plastic stretch would be) and whose nodes remember the largest stretch of their
// row (per node: exchanged with the ghosts and written to frames), declared once
// (core/state_arrays.hpp) and carried by the run without any other file naming it.
#pragma once
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "materials/pmb/pmb.hpp"

namespace pdtest {

inline constexpr const char* kBondPeak = "bond_peak_stretch";
inline constexpr const char* kNodePeak = "node_peak_stretch";

// PMB with a memory: before each breaking pass, every intact bond keeps the largest stretch it has
// had, and every node the largest over its row.
class PeakStretchPmb : public pd::PmbModel {
 public:
  std::vector<pd::StateDeclaration> state_declarations(const pd::Model&) const override {
    pd::StateDeclaration bond{kBondPeak, pd::StateExtent::per_bond};
    bond.checkpoint = true, bond.halo = false, bond.rollback = true, bond.frames = false;
    pd::StateDeclaration node{kNodePeak, pd::StateExtent::per_node};
    node.checkpoint = true, node.halo = true, node.rollback = true, node.frames = true;
    return {bond, node};
  }
  // At rest every stretch is 0, the declared initial value: nothing to fill.
  void initialise_state(pd::Model&) const override {}
  pd::BreakReport break_bonds_and_add_force(pd::Model& m, const pd::Vec3Array& u, pd::Vec3Array& f, double* w,
                                            bool want_energy, double* lost_per_node) const override {
    remember(m, u);
    return PmbModel::break_bonds_and_add_force(m, u, f, w, want_energy, lost_per_node);
  }
  pd::BreakReport break_bonds_and_add_force_overlapped(pd::Model& m, const pd::Vec3Array& u, pd::Vec3Array& f,
                                                       double* w, bool want_energy, double* lost_per_node,
                                                       const pd::GhostsInFlight& u_ghosts) const override {
    u_ghosts.wait();
    return break_bonds_and_add_force(m, u, f, w, want_energy, lost_per_node);
  }
  pd::BreakReport break_bonds(pd::Model& m, const pd::Vec3Array& u, bool want_energy) const override {
    remember(m, u);
    return PmbModel::break_bonds(m, u, want_energy);
  }
  // A piece of a decomposed run runs this law too, not the registry's PMB.
  std::shared_ptr<const pd::BondModel> for_piece(const pd::Model&, const std::vector<std::int32_t>&,
                                                 std::shared_ptr<const pd::BondModel> (*)(const pd::Model&)) const override {
    return std::make_shared<PeakStretchPmb>();
  }

 private:
  static void remember(pd::Model& m, const pd::Vec3Array& u) {
    std::vector<double>& bond = m.state_arrays.find(kBondPeak)->values;
    std::vector<double>& node = m.state_arrays.find(kNodePeak)->values;
    const auto& x = m.nodes.x;
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
      for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
        const auto kk = static_cast<std::size_t>(k);
        if (m.bonds.broken[kk]) continue;
        const auto j = static_cast<std::size_t>(m.bonds.neighbour[kk]);
        double xi2 = 0.0, y2 = 0.0;
        for (std::size_t d = 0; d < 3; ++d) {
          const double xi = x[d][j] - x[d][i], y = xi + u[d][j] - u[d][i];
          xi2 += xi * xi;
          y2 += y * y;
        }
        const double s = (std::sqrt(y2) - std::sqrt(xi2)) / std::sqrt(xi2);
        bond[kk] = std::max(bond[kk], s);
        node[i] = std::max(node[i], s);
      }
  }
};

}  // namespace pdtest
