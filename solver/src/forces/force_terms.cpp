// The registry of force terms: the one list to extend when a new term is added (forces/<term>.cpp
// defines its ForceTerm and its make_<term>_term factory).
#include <algorithm>
#include <stdexcept>

#include "forces/force_term.hpp"

namespace pd {

const std::vector<ForceTermEntry>& force_term_registry() {
  static const std::vector<ForceTermEntry> registry = [] {
    std::vector<ForceTermEntry> r;
    r.push_back({"contact", 1, 3, &make_contact_term,
                 [](const Model&, const Case& c) {
                   return std::string("work: no contact search (") +
                          (c.contact.enabled == "off" ? "contact: off" : "one body and no self_contact") + ")";
                 },
                 "contact_energy"});
    r.push_back({"indenters", 2, 2, &make_indenter_term,
                 [](const Model&, const Case&) { return std::string("work: no indenters"); }, "indenter_energy"});
    r.push_back({"body_force", 3, 1, &make_body_force_term, [](const Model&, const Case&) { return std::string(); }});
    std::sort(r.begin(), r.end(), [](const ForceTermEntry& a, const ForceTermEntry& b) { return a.order < b.order; });
    return r;
  }();
  return registry;
}

const std::vector<std::string>& term_energy_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const ForceTermEntry& entry : force_term_registry())
      if (!entry.energy.empty()) out.push_back(entry.energy);
    return out;
  }();
  return names;
}

std::size_t term_energy_index(const std::string& term) {
  std::size_t k = 0;
  for (const ForceTermEntry& entry : force_term_registry()) {
    if (entry.energy.empty()) continue;
    if (entry.name == term) return k;
    ++k;
  }
  throw std::logic_error("force term '" + term + "' has no energy");
}

double term_energy(const State& s, const std::string& term) {
  const std::size_t k = term_energy_index(term);
  return k < s.term_energies.size() ? s.term_energies[k] : 0.0;
}

void ForceTerm::add_energy(State& s, const std::string& term, double energy) {
  if (s.term_energies.size() < term_energy_names().size()) s.term_energies.resize(term_energy_names().size(), 0.0);
  s.term_energies[term_energy_index(term)] += energy;
}

}  // namespace pd
