// What work the scene needs (see work_plan.hpp).
#include "core/work_plan.hpp"

#include <set>

#include "operator/force_operator.hpp"

namespace pd {

ContactParameters plan_contact(const Case& c, const std::vector<std::int32_t>& block_index, double bond_cutoff) {
  ContactParameters p;
  const std::set<std::int32_t> present(block_index.begin(), block_index.end());
  p.self_contact = c.contact.self_contact;
  if (c.contact.enabled == "on") p.pairs = true;
  else if (c.contact.enabled == "auto") p.pairs = present.size() > 1 || c.contact.self_contact;
  // 1.35·(r_i + r_j) with r = dx/2 (LAMMPS: 1.35·lc; Silling's EMU).
  p.distance = 1.35 * c.grid_spacing;
  p.skin = c.contact.skin > 0.0 ? c.contact.skin : 0.5 * c.grid_spacing;
  p.stiffness_factor = c.contact.stiffness_factor;
  p.bond_cutoff = bond_cutoff;
  return p;
}

std::vector<std::string> work_summary(const ForceOperator& op, const Case& c) {
  std::vector<std::string> lines = op.work_plan(c);
  lines.push_back("work: frames only at output times, history row every " + std::to_string(c.output.history_every) +
                  " step(s)");
  return lines;
}

}  // namespace pd
