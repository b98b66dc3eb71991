// The registry of force terms: the one list to extend when a new term is added (forces/<term>.cpp
// defines its ForceTerm and its make_<term>_term factory).
#include <algorithm>

#include "forces/force_term.hpp"

namespace pd {

const std::vector<ForceTermEntry>& force_term_registry() {
  static const std::vector<ForceTermEntry> registry = [] {
    std::vector<ForceTermEntry> r;
    r.push_back({"contact", 1, 3, &make_contact_term, [](const Model&, const Case& c) {
                   return std::string("work: no contact search (") +
                          (c.contact.enabled == "off" ? "contact: off" : "one body and no self_contact") + ")";
                 }});
    r.push_back({"indenters", 2, 2, &make_indenter_term,
                 [](const Model&, const Case&) { return std::string("work: no indenters"); }});
    r.push_back({"body_force", 3, 1, &make_body_force_term, [](const Model&, const Case&) { return std::string(); }});
    std::sort(r.begin(), r.end(), [](const ForceTermEntry& a, const ForceTermEntry& b) { return a.order < b.order; });
    return r;
  }();
  return registry;
}

}  // namespace pd
