// What work the scene needs (see work_plan.hpp).
#include "core/work_plan.hpp"

#include <cmath>
#include <cstdio>
#include <set>

#include "core/model.hpp"

namespace pd {

namespace {

std::string g(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g", value);
  return buffer;
}

}  // namespace

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

bool breakage_possible(const Model& m) {
  for (double s0 : m.material.critical_pair)
    if (!std::isinf(s0)) return true;
  return false;
}

std::vector<std::string> work_summary(const Model& m, const Case& c) {
  std::vector<std::string> lines;
  lines.push_back("work: bond forces over " + std::to_string(m.bonds.directed() / 2) + " bonds, partial volume " +
                  c.partial_volume + (c.dimension == 2 ? "; 2D (cell grids one bin thick)" : "; 3D"));
  if (m.contact.pairs)
    lines.push_back(std::string("work: contact search (cell list + Verlet list) ") +
                    (m.contact.self_contact ? "between all nodes (self_contact)" : "between blocks") +
                    ", contact distance 2r_s " + g(m.contact.distance) + " m, skin " + g(m.contact.skin) +
                    " m, c_s = " + g(m.contact.stiffness_factor) + "·c");
  else
    lines.push_back(std::string("work: no contact search (") +
                    (c.contact.enabled == "off" ? "contact: off" : "one body and no self_contact") + ")");
  if (m.indenters.empty()) lines.push_back("work: no indenters");
  for (const auto& ind : m.indenters)
    lines.push_back("work: indenter '" + ind.name + "' (" + ind.shape +
                    (ind.shape == "plane" ? "" : ", R " + g(ind.radius) + " m") + ", K " + g(ind.stiffness) +
                    " N/m⁵, velocity (" + g(ind.velocity[0]) + ", " + g(ind.velocity[1]) + ", " +
                    g(ind.velocity[2]) + ") m/s)");
  lines.push_back(breakage_possible(m) ? "work: breakage test after every step"
                                       : "work: no breakage test (every block unbreakable)");
  lines.push_back("work: frames only at output times, history row every " + std::to_string(c.output.history_every) +
                  " step(s)");
  return lines;
}

}  // namespace pd
