// The extra columns of history.csv, header and values together (run/history_columns.hpp).
#include "run/history_columns.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/exact_sum.hpp"
#include "core/reactions.hpp"
#include "forces/force_term.hpp"
#include "parallel/local_model.hpp"

namespace pd {

void HistoryColumns::add(std::vector<std::string> names, Fill fill) {
  groups_.emplace_back(names.size(), std::move(fill));
  names_.insert(names_.end(), names.begin(), names.end());
}

// The fixed columns that every case has, whatever its integrator, contact, indenters or breaking
// (issue 16 item 6: a program reads the same names from every run), then one triple per indenter
// and per output.reactions set, which the case names.
const std::vector<std::string>& fixed_history_columns() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out = term_energy_names();  // contact_energy, indenter_energy
    for (const char* name : {"broken_bond_energy", "contact_rebuilds", "mode"}) out.push_back(name);
    return out;
  }();
  return names;
}

HistoryColumns::HistoryColumns(const Model& model, const Case& c, const Integrator* integrator,
                               const NeighbourList* contact_list, const Decomposed* dec) {
  const Model* m = &model;
  // A term the case does not have is 0: the operator zeroes every term's energy before the terms
  // add to them (operator/force_operator.cpp), and the broken-bond energy stays 0 when nothing can break.
  std::vector<std::string> energies = term_energy_names();
  energies.push_back("broken_bond_energy");
  add(energies, [](const HistoryInputs& in, std::vector<double>& out) {
    for (std::size_t k = 0; k < term_energy_names().size(); ++k)
      out.push_back(k < in.state.term_energies.size() ? in.state.term_energies[k] : 0.0);
    out.push_back(in.broken_energy);  // docs/theory.md C4 with breaking
  });
  // The operator's list (contact_list; on a decomposed run the piece's: every rank builds together).
  const NeighbourList* list = contact_list ? contact_list : &model.contact_list;
  add({"contact_rebuilds"}, [m, list](const HistoryInputs&, std::vector<double>& out) {
    out.push_back(m->contact.pairs ? static_cast<double>(list->rebuilds()) : 0.0);
  });
  // 1 a quasi-static load step, 0 a dynamic one (explicit or implicit): integrators/integrator.hpp.
  add({"mode"}, [integrator](const HistoryInputs&, std::vector<double>& out) {
    out.push_back(integrator ? static_cast<double>(integrator->step_mode().value_or(0)) : 0.0);
  });
  for (std::size_t k = 0; k < model.indenters.size(); ++k) {
    std::vector<std::string> names;
    for (const char* axis : {"fx", "fy", "fz"}) names.push_back("indenter_" + model.indenters[k].name + "_" + axis);
    add(names, [k](const HistoryInputs& in, std::vector<double>& out) {
      for (std::size_t d = 0; d < 3; ++d)  // the reaction on the indenter: minus its force on the body
        out.push_back(k < in.state.indenter_force.size() ? -in.state.indenter_force[k][d] : 0.0);
    });
  }
  for (const auto& set : c.output.reactions) {
    std::vector<std::string> names;
    for (const char* axis : {"fx", "fy", "fz"}) names.push_back("reaction_" + set + "_" + axis);
    add(names, [m, set, dec](const HistoryInputs& in, std::vector<double>& out) {
      std::array<double, 3> r{};
      if (dec) {
        // The piece's terms to rank 0, which adds them in the serial order: the serial bits, and
        // no gather of the whole state (rank 0's values are the ones written).
        const LocalPiece& piece = dec->piece();
        const ReactionTerms terms = reaction_terms(*m, in.state, set, in.t, piece.global, piece.global_nodes);
        r = sum_reaction_terms(*m, dec->gather_keyed(terms.key, terms.value), piece.global_nodes);
      } else {
        r = reaction_force(*m, in.state, set, in.t);
      }
      for (double component : r) out.push_back(component);
    });
  }
  for (const auto& set : c.output.probes) add_probe(model, set, dec);
  if (names_.size() < fixed_history_columns().size() ||
      !std::equal(fixed_history_columns().begin(), fixed_history_columns().end(), names_.begin()))
    throw Error("history.csv: the fixed columns are out of step with fixed_history_columns()");  // a bug here
}

void HistoryColumns::add_probe(const Model& model, const std::string& set_name, const Decomposed* dec) {
  const NodeSet* set = model.nodes.find_set(set_name);
  if (!set) throw Error("output.probes: node set '" + set_name + "' is not in the node file");
  // The set's nodes this rank owns (a ghost is its owner's): the whole set on one rank.
  std::vector<std::size_t> nodes;
  for (std::size_t i = 0; i < set->member.size(); ++i)
    if (set->member[i] && (!dec || dec->piece().owned[i])) nodes.push_back(i);
  std::vector<std::string> names;
  for (const char* what : {"ux", "uy", "uz", "vx", "vy", "vz"}) names.push_back("probe_" + set_name + "_" + what);
  const std::vector<double>* volume = &model.nodes.volume;
  add(names, [nodes, volume, dec](const HistoryInputs& in, std::vector<double>& out) {
    // Σ V u / Σ V and Σ V v / Σ V over the set, the sums exact (core/exact_sum.hpp): the same bits
    // in any order, so on any rank and thread count.
    ExactSum sums[7];
    for (std::size_t i : nodes) {
      const double weight = (*volume)[i];
      for (std::size_t d = 0; d < 3; ++d) {
        sums[d].add(weight * in.state.u[d][i]);
        sums[3 + d].add(weight * in.state.v[d][i]);
      }
      sums[6].add(weight);
    }
    if (dec) dec->reduce(sums, 7);
    const double total = sums[6].value();
    for (int k = 0; k < 6; ++k) out.push_back(sums[k].value() / total);
  });
}

void HistoryColumns::fill(HistoryRow& row, const HistoryInputs& in) const {
  for (const auto& [count, fill] : groups_) {
    const std::size_t before = row.extra.size();
    fill(in, row.extra);
    if (row.extra.size() != before + count)  // a group that fills other than it names: a bug here
      throw Error("history.csv: a column group gave " + std::to_string(row.extra.size() - before) + " values for " +
                  std::to_string(count) + " columns");
  }
}

}  // namespace pd
