// The scene's own history.csv columns (run/history_columns.hpp): names and values come in the
// same order and number, for each combination of contact, indenters and breaking.
#include <gtest/gtest.h>

#include <cmath>

#include "integrators/integrator.hpp"
#include "lattice.hpp"
#include "operator/force_operator.hpp"
#include "run/history_columns.hpp"

namespace {

pd::Model scene(bool contact, int indenters, bool breakable) {
  pd::Model m;
  m.contact.pairs = contact;
  for (int k = 0; k < indenters; ++k) {
    pd::IndenterSettings ind;
    ind.name = "i" + std::to_string(k);
    m.indenters.push_back(ind);
  }
  m.material.critical_pair = {breakable ? 0.01 : HUGE_VAL};
  return m;
}

}  // namespace

// The columns every case has after wall_time, whatever its integrator, contact, indenters or
// breaking (issue 16 item 6): the same names in the same order, 0 for what the case lacks.
const std::vector<std::string> kFixed{"contact_energy", "indenter_energy", "broken_bond_energy", "contact_rebuilds",
                                      "mode"};

TEST(HistoryColumns, APlainBodyHasTheFixedColumnsAllZero) {
  const pd::Model m = scene(false, 0, false);
  const pd::HistoryColumns columns(m, pd::Case{});
  EXPECT_EQ(columns.names(), kFixed);
  EXPECT_EQ(pd::fixed_history_columns(), kFixed);
  pd::HistoryRow row;
  const pd::State state(0);
  columns.fill(row, pd::HistoryInputs{state, 0.0, 0.0});
  EXPECT_EQ(row.extra, (std::vector<double>{0.0, 0.0, 0.0, 0.0, 0.0}));
}

TEST(HistoryColumns, IndentersAndBreakingAddOnlyTheNamedTriplesAfterTheFixedColumns) {
  const pd::Model m = scene(false, 2, true);
  const pd::HistoryColumns columns(m, pd::Case{});
  std::vector<std::string> expected = kFixed;
  for (const char* name : {"indenter_i0_fx", "indenter_i0_fy", "indenter_i0_fz", "indenter_i1_fx", "indenter_i1_fy",
                           "indenter_i1_fz"})
    expected.push_back(name);
  EXPECT_EQ(columns.names(), expected);
  pd::State state(0);
  state.term_energies = {2.0, 3.0};  // contact's, then the indenters' (no longer added into contact_energy)
  state.indenter_force = {{1.0, 2.0, 3.0}};  // the second indenter's force not yet computed: 0
  pd::HistoryRow row;
  columns.fill(row, pd::HistoryInputs{state, 0.0, 5.0});
  EXPECT_EQ(row.extra, (std::vector<double>{2.0, 3.0, 5.0, 0.0, 0.0, -1.0, -2.0, -3.0, 0.0, 0.0, 0.0}));  // reactions: minus the force
  EXPECT_EQ(row.extra.size(), columns.names().size());
}

TEST(HistoryColumns, ContactGivesItsEnergyAndTheListBuildsInTheFixedColumns) {
  const pd::Model m = scene(true, 0, false);
  const pd::HistoryColumns columns(m, pd::Case{});
  EXPECT_EQ(columns.names(), kFixed);
  pd::State state(0);
  state.term_energies = {0.25};  // contact's; the indenters' not yet computed: 0
  pd::HistoryRow row;
  columns.fill(row, pd::HistoryInputs{state, 0.0, 0.0});
  EXPECT_EQ(row.extra, (std::vector<double>{0.25, 0.0, 0.0, 0.0, 0.0}));
}

// `mode` in every history.csv: 1 for a quasi-static load step, 0 for a dynamic one (formats.md §4).
TEST(HistoryColumns, ModeIsOneForQuasiStaticLoadStepsAndZeroForDynamicSteps) {
  const pd::Case c = pdtest::lattice_case(2, "plane_stress", 1e-3, 3.015e-3, 1e9, 1000.0, -1.0, 1e-3);
  pd::Model m = pd::build_model(c, pdtest::cubic_lattice(4, 4, 1, 1e-3, 2, 1e-3));
  pd::ForceOperator op(m);
  const std::vector<std::pair<std::string, double>> expected{
      {"verlet", 0.0}, {"adaptive", 0.0}, {"implicit", 0.0}, {"quasi_static", 1.0}};
  for (const auto& [name, mode] : expected) {
    auto integrator = pd::integrator_registry().get(name)(op);
    const pd::HistoryColumns columns(m, c, integrator.get());
    ASSERT_EQ(columns.names(), kFixed) << name;
    pd::HistoryRow row;
    const pd::State state(m.nodes.size());
    columns.fill(row, pd::HistoryInputs{state, 0.0, 0.0});
    EXPECT_EQ(row.extra[4], mode) << name;
  }
}
