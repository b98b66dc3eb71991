// Decides from the case whether the scene needs contact at all (the operator builds the other terms
// only when the case has them, operator/force_operator.hpp), and the work plan run.log prints.
#pragma once
#include <string>
#include <vector>

#include "core/case.hpp"
#include "core/neighbour_list.hpp"

namespace pd {

// contact.enabled: off → no pairs; on → pairs; auto → pairs when the node file holds more than one
// block or self_contact is set. Between different blocks always, inside a block only with
// self_contact. Contact distance 2r_s = 1.35·(r_i + r_j) with r = dx/2 (docs/theory.md T8).
ContactParameters plan_contact(const Case& c, const std::vector<std::int32_t>& block_index, double bond_cutoff);

class ForceOperator;

// One line per kind of work, for run.log: the operator's plan (bonds, every registered term,
// breaking) and the output schedule.
std::vector<std::string> work_summary(const ForceOperator& op, const Case& c);

}  // namespace pd
