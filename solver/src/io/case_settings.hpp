// The settings sections of case.json (time, adaptive, quasi_static, implicit, mixed, output,
// contact), each a table of its keys (io/settings_table.hpp) bound to the fields of a Case: the
// reader fills them in, case_keys() and pdsolve --describe read the keys and the defaults.
#pragma once
#include <vector>

#include "core/case.hpp"
#include "io/settings_table.hpp"

namespace pd {

// The sections, in the order the reader reads them, each Setting pointing into `c`.
std::vector<SettingsSection> settings_sections(Case& c);

}  // namespace pd
