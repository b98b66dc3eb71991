// Decides from the case what work a run needs, so the solver does only that and says so at start:
// no contact search for a single body (unless self-contact is asked for), no breakage test for
// unbreakable materials, indenters only when the case has some.
#pragma once
#include <string>
#include <vector>

#include "core/case.hpp"
#include "core/verlet_list.hpp"

namespace pd {

struct Model;

// contact.enabled: off → no pairs; on → pairs; auto → pairs when the node file holds more than one
// block or self_contact is set. Between different blocks always, inside a block only with
// self_contact. Contact distance 2r_s = 1.35·(r_i + r_j) with r = dx/2 (validation.md F4).
ContactParameters plan_contact(const Case& c, const std::vector<std::int32_t>& block_index, double bond_cutoff);

// True when some block pair can break (a bond between an unbreakable block and any other never does).
bool breakage_possible(const Model& model);

// One line per kind of work, for run.log.
std::vector<std::string> work_summary(const Model& model, const Case& c);

}  // namespace pd
