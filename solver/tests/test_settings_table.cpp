// The settings tables (io/case_settings.cpp) against the reader and --describe: for every key of
// every settings section with a range, a value just outside it is refused by parse_case with the
// table's bound in the message, and one just inside is accepted and read unchanged; --describe
// prints the same bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "core/error.hpp"
#include "io/case_reader.hpp"
#include "io/case_settings.hpp"
#include "io/describe.hpp"

namespace {

using json = nlohmann::json;

const char* const kCase = R"({
  "format_version": 1, "nodes_file": "nodes.vtu", "dimension": 3, "analysis": "3d",
  "grid_spacing": 0.001, "horizon": 0.003,
  "blocks": [{"id": 1, "name": "bar", "density": 1000.0, "youngs_modulus": 1.0e9}],
  "time": {"end": 1.0},
  "output": {"every_time": 0.1}
})";

// A bound as the reader writes it in a message: 0, 0.5, 1.
std::string text(double bound) {
  std::ostringstream out;
  out << bound;
  return out.str();
}

// The value a setting holds, as a double (a number, an integer, or time.dt's number);
// empty for a name, a flag or an empty optional.
std::optional<double> value_of(const pd::Setting& s) {
  return std::visit(
      [](auto field) -> std::optional<double> {
        using Field = decltype(field);
        if constexpr (std::is_same_v<Field, double*> || std::is_same_v<Field, int*> ||
                      std::is_same_v<Field, std::int64_t*>)
          return static_cast<double>(*field);
        if constexpr (std::is_same_v<Field, std::optional<double>*> || std::is_same_v<Field, std::optional<std::int64_t>*>)
          return *field ? std::optional<double>(static_cast<double>(**field)) : std::nullopt;
        if constexpr (std::is_same_v<Field, pd::RuleOrNumber>) return *field.number;
        return std::nullopt;
      },
      s.field);
}

bool is_integer(const pd::Setting& s) {
  return std::holds_alternative<int*>(s.field) || std::holds_alternative<std::int64_t*>(s.field) ||
         std::holds_alternative<std::optional<std::int64_t>*>(s.field);
}

// kCase with section.key = value (and, for output's every_time / every_steps, the other one null:
// exactly one of them must be set).
std::string case_with(const std::string& section, const std::string& key, const json& value) {
  json root = json::parse(kCase);
  root[section][key] = value;
  if (section == "output" && (key == "every_time" || key == "every_steps"))
    root["output"][key == "every_time" ? "every_steps" : "every_time"] = nullptr;
  return root.dump();
}

struct Probe {
  json value;
  std::string bound;  // what the message must say, e.g. "> 0", "below 1", "between 1 and 1000"
};

// Values just outside the setting's range, each with the bound the refusal must name.
std::vector<Probe> outside(const pd::Setting& s) {
  std::vector<Probe> out;
  if (is_integer(s)) {
    const std::string range = "between " + std::to_string(s.lowest) + " and " + std::to_string(s.highest);
    if (s.lowest > std::numeric_limits<std::int64_t>::min()) out.push_back({s.lowest - 1, range});
    if (s.highest < std::numeric_limits<std::int64_t>::max()) out.push_back({s.highest + 1, range});
    return out;
  }
  const bool closed = s.minimum && s.maximum;
  const std::string between = closed ? "between " + text(*s.minimum) + " and " + text(*s.maximum) : "";
  if (s.above) out.push_back({*s.above, "> " + text(*s.above)});
  if (s.minimum) out.push_back({std::nextafter(*s.minimum, -HUGE_VAL), closed ? between : "≥ " + text(*s.minimum)});
  if (s.below) out.push_back({*s.below, "below " + text(*s.below)});
  if (s.maximum) out.push_back({std::nextafter(*s.maximum, HUGE_VAL), between});
  return out;
}

// Values just inside the range: its ends where they are included, else one step in.
std::vector<json> inside(const pd::Setting& s) {
  if (is_integer(s)) return {s.lowest, s.highest};
  std::vector<json> in;
  if (s.above) in.push_back(std::nextafter(*s.above, HUGE_VAL));
  if (s.minimum) in.push_back(*s.minimum);
  if (s.below) in.push_back(std::nextafter(*s.below, -HUGE_VAL));
  if (s.maximum) in.push_back(*s.maximum);
  return in;
}

bool has_range(const pd::Setting& s) {
  return is_integer(s) || s.above || s.minimum || s.below || s.maximum;
}

TEST(SettingsTable, EveryRangeIsTheReadersAndDescribes) {
  pd::Case defaults;
  const json described = pd::describe_case()["keys"];
  int ranged = 0;
  const std::vector<pd::SettingsSection> sections = pd::settings_sections(defaults);
  for (std::size_t i = 0; i < sections.size(); ++i)
    for (std::size_t k = 0; k < sections[i].settings.size(); ++k) {
      const pd::SettingsSection& section = sections[i];
      const pd::Setting& s = section.settings[k];
      if (!has_range(s)) continue;
      ++ranged;
      const std::string key = section.name + "." + s.key;
      for (const Probe& probe : outside(s)) {
        try {
          pd::parse_case(case_with(section.name, s.key, probe.value), "run/case.json");
          ADD_FAILURE() << key << " = " << probe.value.dump() << " was accepted";
        } catch (const pd::Error& e) {
          const std::string message = e.what();
          EXPECT_EQ(message.rfind("run/case.json: " + key + ": must be ", 0), 0u) << message;
          EXPECT_NE(message.find(probe.bound), std::string::npos) << message << " does not say " << probe.bound;
          EXPECT_NE(message.find("got " + probe.value.dump()), std::string::npos) << message;
        }
      }
      for (const json& value : inside(s)) {
        pd::Case c;
        EXPECT_NO_THROW(c = pd::parse_case(case_with(section.name, s.key, value), "run/case.json"))
            << key << " = " << value.dump();
        EXPECT_EQ(value_of(pd::settings_sections(c)[i].settings[k]), value.get<double>()) << key;
      }
      // --describe prints the table's bounds: an integer's as minimum and maximum.
      const json& d = described.at(key);
      if (is_integer(s)) {
        EXPECT_EQ(d.at("minimum").get<std::int64_t>(), s.lowest) << key;
        EXPECT_EQ(d.contains("maximum") ? d["maximum"].get<std::int64_t>() : std::numeric_limits<std::int64_t>::max(),
                  s.highest)
            << key;
        continue;
      }
      for (const auto& [name, bound] : {std::pair{"above", s.above}, std::pair{"minimum", s.minimum},
                                        std::pair{"below", s.below}, std::pair{"maximum", s.maximum}}) {
        EXPECT_EQ(d.contains(name), bound.has_value()) << key << " " << name;
        if (bound && d.contains(name)) EXPECT_EQ(d[name].get<double>(), *bound) << key << " " << name;
      }
    }
  EXPECT_GE(ranged, 40);  // every settings section has ranged keys; a table that lost them fails here
}

// The keys case_keys() lists for a settings section are its table's, in the table's order.
TEST(SettingsTable, CaseKeysAreTheTables) {
  pd::Case c;
  for (const pd::SettingsSection& section : pd::settings_sections(c)) {
    std::vector<std::string> keys;
    for (const pd::Setting& s : section.settings) keys.push_back(s.key);
    EXPECT_EQ(pd::case_keys().at(section.name), keys) << section.name;
  }
}

// One Newton block: quasi_static and implicit read the same keys into NewtonSettings, but for the
// name of the correction tolerance and the default of max_iterations.
TEST(SettingsTable, QuasiStaticAndImplicitShareNewtonsBlock) {
  json root = json::parse(kCase);
  root["quasi_static"] = {{"tol", 1e-7}, {"kd", 7}, {"cg_max_iterations", 9}, {"dt_max", 0.5}};
  root["implicit"] = {{"newton_tol", 1e-7}, {"kd", 7}, {"cg_max_iterations", 9}, {"dt_max", 0.5}, {"tol", 0.25}};
  const pd::Case c = pd::parse_case(root.dump(), "run/case.json");
  const pd::NewtonSettings& q = c.quasi_static;
  const pd::NewtonSettings& m = c.implicit;
  for (const pd::NewtonSettings* n : {&q, &m}) {
    EXPECT_EQ(n->newton_tol, 1e-7);
    EXPECT_EQ(n->kd, 7);
    EXPECT_EQ(n->cg_max_iterations, 9);
    EXPECT_EQ(n->dt_max, 0.5);
  }
  EXPECT_EQ(c.implicit.tol, 0.25);  // implicit's own error tolerance, not Newton's
  EXPECT_EQ(q.max_iterations, 30);
  EXPECT_EQ(m.max_iterations, 20);
}

}  // namespace
