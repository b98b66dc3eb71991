// The scene's own columns of history.csv (formats.md §4), after wall_time: each column group is
// declared once with its names and the values it puts in a row, so header and rows cannot drift.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "core/case.hpp"
#include "core/model.hpp"
#include "core/state.hpp"
#include "integrators/integrator.hpp"
#include "io/output.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

// What a row's extra values are computed from.
struct HistoryInputs {
  const State& state;    // the run's (a decomposed run's: this rank's piece's, with the totals)
  double t;              // [s]
  double broken_energy;  // Σ energy of bonds at the moment they broke [J]
};

// The columns after wall_time that every history.csv has, in order: the force terms' energies
// (forces/force_term.hpp term_energy_names: contact_energy, indenter_energy), broken_bond_energy,
// contact_rebuilds, mode.
const std::vector<std::string>& fixed_history_columns();

class HistoryColumns {
 public:
  // fixed_history_columns() for every case (a term the case lacks is 0), then each indenter's
  // reaction, each output.reactions set's and each output.probes set's mean motion (formats.md §4).
  // contact_list: the Verlet list whose builds the contact_rebuilds column counts (the operator's;
  // null: model's). On a decomposed run (dec), model is this rank's piece and a row's inputs its
  // own state: fill() is then collective (a reaction's terms go to rank 0, whose row is written).
  HistoryColumns(const Model& model, const Case& c, const Integrator* integrator = nullptr,
                 const NeighbourList* contact_list = nullptr, const Decomposed* dec = nullptr);
  HistoryColumns(const HistoryColumns&) = delete;
  HistoryColumns& operator=(const HistoryColumns&) = delete;

  // The names after wall_time, in order (OutputWriter writes them into the header).
  const std::vector<std::string>& names() const { return names_; }
  // Appends the row's values to row.extra, one per name.
  void fill(HistoryRow& row, const HistoryInputs& in) const;

 private:
  using Fill = std::function<void(const HistoryInputs&, std::vector<double>&)>;
  void add(std::vector<std::string> names, Fill fill);
  // output.probes: the set's volume-weighted mean displacement and velocity, probe_<set>_ux … _vz.
  void add_probe(const Model& model, const std::string& set, const Decomposed* dec);
  std::vector<std::string> names_;
  std::vector<std::pair<std::size_t, Fill>> groups_;  // (its column count, what fills them)
};

}  // namespace pd
