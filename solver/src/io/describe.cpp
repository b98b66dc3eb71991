// pdsolve --describe: the case.json keys the reader accepts, described from the structs' own
// defaults (core/case.hpp), the registries' keys and the settings sections' tables
// (io/case_settings.cpp), checked against the reader's key lists.
#include "io/describe.hpp"

#include <limits>
#include <optional>
#include <set>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

#include "core/case.hpp"
#include "core/error.hpp"
#include "core/material.hpp"
#include "core/partial_volume.hpp"
#include "core/surface_correction.hpp"
#include "forces/indenter.hpp"
#include "integrators/integrator.hpp"
#include "io/case_reader.hpp"
#include "io/case_settings.hpp"
#include "io/output.hpp"

namespace pd {

namespace {

using json = nlohmann::json;

template <class T>
json value_or_null(const std::optional<T>& v) {
  return v ? json(*v) : json(nullptr);
}

json spec(const std::string& type, json extra = json::object()) {
  json s = {{"type", type}};
  s.update(extra);
  return s;
}
json required(const std::string& type, json extra = json::object()) {
  extra["required"] = true;
  return spec(type, std::move(extra));
}
json defaulted(const std::string& type, json value, json extra = json::object()) {
  extra["default"] = std::move(value);
  return spec(type, std::move(extra));
}

// One key of a settings section (io/settings_table.hpp): its type from its field, its default from
// the field's value in a fresh Case, its range and choices as the reader checks them.
json describe_setting(const Setting& s) {
  json extra = json::object();
  if (s.above) extra["above"] = *s.above;
  if (s.minimum) extra["minimum"] = *s.minimum;
  if (s.below) extra["below"] = *s.below;
  if (s.maximum) extra["maximum"] = *s.maximum;
  if (!s.choices.empty()) extra["choices"] = s.choices;
  if (!s.unit.empty()) extra["unit"] = s.unit;
  if (!s.note.empty()) extra["note"] = s.note;
  const auto integer_range = [&] {
    extra["minimum"] = s.lowest;
    if (s.highest != std::numeric_limits<std::int64_t>::max()) extra["maximum"] = s.highest;
  };
  const auto [type, value] = std::visit(
      [&](auto field) -> std::pair<std::string, json> {
        using Field = decltype(field);
        if constexpr (std::is_same_v<Field, double*>) return {"number", *field};
        if constexpr (std::is_same_v<Field, std::optional<double>*>) return {"number", value_or_null(*field)};
        if constexpr (std::is_same_v<Field, int*> || std::is_same_v<Field, std::int64_t*>) {
          integer_range();
          return {"integer", *field};
        }
        if constexpr (std::is_same_v<Field, std::optional<std::int64_t>*>) {
          integer_range();
          return {"integer", value_or_null(*field)};
        }
        if constexpr (std::is_same_v<Field, bool*>) return {"boolean", *field};
        if constexpr (std::is_same_v<Field, std::string*>) return {"string", *field};
        if constexpr (std::is_same_v<Field, std::vector<std::string>*>) return {"strings", *field};
        if constexpr (std::is_same_v<Field, RuleOrNumber>) return {"number_or_choice", *field.rule};
      },
      s.field);
  return s.required ? required(type, extra) : defaulted(type, value, extra);
}

}  // namespace

json describe_case() {
  const Case c;
  const InitialCondition ic;
  const IndenterSettings ind;

  // The keys outside the settings sections: ranges and hand-checked choices as case_reader.cpp
  // enforces them; defaults from the structs.
  json keys = json::object();
  keys["format_version"] = required("integer", {{"choices", {kCaseFormatVersion}}});
  keys["case"] = defaulted("string", c.name);
  keys["title"] = defaulted("string", c.title);
  keys["source"] = defaulted("string", c.source);
  keys["nodes_file"] = required("string", {{"note", "relative to the directory of case.json; not empty"}});
  keys["output_dir"] = defaulted("string", kDefaultOutputDir, {{"note", "relative to the directory of case.json (the run folder), and inside it: an absolute path, .. out of it or a symbolic link out of it is refused"}});
  keys["dimension"] = required("integer", {{"minimum", 2}, {"maximum", 3}});
  keys["analysis"] = required("string", {{"choices", analysis_registry().keys()}, {"note", "must fit dimension"}});
  keys["thickness"] = defaulted("number", c.thickness,
                              {{"above", 0.0}, {"unit", "m"}, {"required_if", "dimension == 2"},
                               {"note", "unused in 3D"}});
  keys["grid_spacing"] = required("number", {{"above", 0.0}, {"unit", "m"}});
  keys["horizon"] = required("number", {{"above", 0.0}, {"unit", "m"}});
  keys["partial_volume"] = defaulted("string", c.partial_volume, {{"choices", partial_volume_registry().keys()}});
  keys["surface_correction"] = defaulted("string", c.surface_correction,
                                         {{"choices", surface_correction_registry().keys()}});
  keys["blocks"] = required("list", {{"note", "at least one; blocks[k].id == k + 1"}});
  keys["blocks[].id"] = required("integer", {{"minimum", 1}, {"note", "its position, counted from 1"}});
  keys["blocks[].name"] = required("string");
  keys["no_fail_sets"] = defaulted("strings", c.no_fail_sets);
  keys["node_sets"] = defaulted("strings", c.node_sets);
  keys["boundary_conditions"] = defaulted("list", json::array());
  keys["boundary_conditions[].set"] = required("string");
  keys["boundary_conditions[].kind"] = required("string", {{"choices", {"displacement", "velocity", "body_force"}}});
  keys["boundary_conditions[].component"] = required("integer", {{"minimum", 0}, {"maximum", 2}});
  keys["boundary_conditions[].times"] = required("numbers", {{"unit", "s"}, {"note", "strictly increasing, not empty"}});
  keys["boundary_conditions[].values"] = required("numbers", {{"note", "as many as times"}});
  keys["initial_conditions"] = defaulted("list", json::array());
  keys["initial_conditions[].set"] = required("string");
  keys["initial_conditions[].kind"] = required("string", {{"choices", {"displacement", "velocity"}}});
  keys["initial_conditions[].component"] = required("integer", {{"minimum", 0}, {"maximum", 2}});
  keys["initial_conditions[].value"] = required("number");
  keys["initial_conditions[].gradient"] = defaulted("number", ic.gradient, {{"note", "kind displacement only: u = value + gradient·x[component]"}});
  keys["cracks"] = defaulted("list", json::array());
  keys["cracks[].from"] = required("numbers", {{"length", 3}, {"unit", "m"}});
  keys["cracks[].to"] = required("numbers", {{"length", 3}, {"unit", "m"}});
  keys["breaking_order"] = defaulted("string", c.breaking_order, {{"choices", {"thesis", "lammps"}}});
  keys["damping"] = defaulted("number", c.damping, {{"minimum", 0.0}, {"unit", "1/s"}});
  keys["indenters"] = defaulted("list", json::array());
  keys["indenters[].name"] = required("string", {{"note", "[A-Za-z_][A-Za-z0-9_]*, unique"}});
  keys["indenters[].shape"] = required("string", {{"choices", indenter_shape_registry().keys()}});
  keys["indenters[].radius"] = defaulted("number", ind.radius,
                                       {{"above", 0.0}, {"unit", "m"}, {"required_if", "shape != plane"}});
  keys["indenters[].centre"] = required("numbers", {{"length", 3}, {"unit", "m"}});
  keys["indenters[].velocity"] = defaulted("numbers", ind.velocity, {{"length", 3}, {"unit", "m/s"}});
  keys["indenters[].normal"] = defaulted("numbers", ind.normal,
                                       {{"length", 3}, {"required_if", "shape == plane"}, {"note", "made a unit vector"}});
  keys["indenters[].axis"] = defaulted("numbers", kDefaultCylinderAxis,
                                     {{"length", 3}, {"note", "cylinder only; made a unit vector"}});
  keys["indenters[].stiffness"] = required("number", {{"above", 0.0}, {"unit", "N/m⁵"}});
  // The settings sections, from their tables (io/case_settings.cpp).
  Case defaults;
  for (const SettingsSection& section : settings_sections(defaults)) {
    json extra = json::object();
    if (!section.note.empty()) extra["note"] = section.note;
    keys[section.name] = section.required ? required("object", extra) : defaulted("object", json::object(), extra);
    for (const Setting& setting : section.settings) keys[section.name + "." + setting.key] = describe_setting(setting);
  }
  keys["figures"] = defaulted("object", json::object(), {{"note", "postprocess only: checked to be an object"}});

  // Every key the reader accepts is described, and nothing else (blocks: id, name + the material's).
  std::set<std::string> accepted = {"blocks[].id", "blocks[].name"};
  const json material = describe_material_keys();  // a named object: items() does not extend a temporary
  for (const auto& item : material.items()) {
    keys["blocks[]." + item.key()] = item.value();
    accepted.insert("blocks[]." + item.key());
  }
  for (const auto& [where, names] : case_keys())
    for (const auto& name : names) accepted.insert(where.empty() ? name : where + "." + name);
  for (const auto& item : keys.items())
    if (!accepted.count(item.key())) throw Error("describe: '" + item.key() + "' is not a key case_reader accepts");
  for (const auto& name : accepted)
    if (!keys.contains(name)) throw Error("describe: the reader accepts '" + name + "', which is not described");

  return {{"describe_version", 1},
          {"keys", keys},
          {"registries",
           {{"analysis", analysis_registry().keys()},
            {"integrator", integrator_registry().keys()},
            {"partial_volume", partial_volume_registry().keys()},
            {"surface_correction", surface_correction_registry().keys()},
            {"indenter_shape", indenter_shape_registry().keys()}}}};
}

}  // namespace pd
