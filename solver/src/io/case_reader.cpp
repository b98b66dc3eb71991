// case.json → pd::Case, with every key and value checked against pipeline/formats.md §3.
#include "io/case_reader.hpp"

#include "io/read_file.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <type_traits>
#include <utility>
#include <variant>

#include "core/error.hpp"
#include "core/partial_volume.hpp"
#include "core/surface_correction.hpp"
#include "forces/indenter.hpp"
#include "io/case_settings.hpp"
#include "materials/bond_model.hpp"

namespace pd {

namespace {

using json = nlohmann::json;

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1] ? 1u : 0u)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string show(const json& j) {
  std::string s = j.dump();
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& name : names) out += (out.empty() ? "" : ", ") + name;
  return out;
}

// " (did you mean 'x'?)" for the known name within 3 edits of `name`, else "".
std::string closest(const std::string& name, const std::vector<std::string>& known) {
  std::string best;
  std::size_t best_distance = 1000;
  for (const auto& k : known)
    if (const std::size_t d = edit_distance(name, k); d < best_distance) best_distance = d, best = k;
  return best_distance <= 3 ? " (did you mean '" + best + "'?)" : std::string();
}

class Checker {
 public:
  explicit Checker(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw Error(file_ + ": " + key + ": " + what);
  }

  // Unknown keys are errors that name the closest known key.
  void known_keys(const json& obj, const std::string& where, const std::vector<std::string>& allowed) const {
    for (const auto& item : obj.items()) {
      if (std::find(allowed.begin(), allowed.end(), item.key()) != allowed.end()) continue;
      std::string best;
      std::size_t best_distance = 1000;
      for (const auto& a : allowed) {
        const std::size_t d = edit_distance(item.key(), a);
        if (d < best_distance) best_distance = d, best = a;
      }
      const std::string key = where.empty() ? item.key() : where + "." + item.key();
      fail(key, "unknown key" + (best_distance <= 3 ? " (did you mean '" + best + "'?)" : std::string()));
    }
  }

  const json* optional(const json& obj, const std::string& name) const {
    auto it = obj.find(name);
    return it == obj.end() ? nullptr : &*it;
  }
  const json& required(const json& obj, const std::string& name, const std::string& key) const {
    const json* j = optional(obj, name);
    if (!j) fail(key, "required key is missing");
    return *j;
  }

  const json& object(const json& j, const std::string& key) const {
    if (!j.is_object()) fail(key, "must be an object, got " + show(j));
    return j;
  }
  const json& array(const json& j, const std::string& key) const {
    if (!j.is_array()) fail(key, "must be a list, got " + show(j));
    return j;
  }
  std::string string(const json& j, const std::string& key) const {
    if (!j.is_string()) fail(key, "must be a string, got " + show(j));
    return j.get<std::string>();
  }
  double number(const json& j, const std::string& key) const {
    if (!j.is_number()) fail(key, "must be a number, got " + show(j));
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail(key, "must be finite, got " + show(j));
    return v;
  }
  double positive(const json& j, const std::string& key) const {
    const double v = number(j, key);
    if (!(v > 0.0)) fail(key, "must be > 0, got " + show(j));
    return v;
  }
  double non_negative(const json& j, const std::string& key) const {
    const double v = number(j, key);
    if (v < 0.0) fail(key, "must be ≥ 0, got " + show(j));
    return v;
  }
  std::int64_t integer(const json& j, const std::string& key, std::int64_t minimum, std::int64_t maximum) const {
    if (!j.is_number_integer()) fail(key, "must be an integer, got " + show(j));
    const auto v = j.get<std::int64_t>();
    if (v < minimum || v > maximum)
      fail(key, "must be between " + std::to_string(minimum) + " and " + std::to_string(maximum) + ", got " + show(j));
    return v;
  }
  std::vector<std::string> strings(const json& j, const std::string& key) const {
    std::vector<std::string> out;
    for (std::size_t k = 0; k < array(j, key).size(); ++k)
      out.push_back(string(j[k], key + "[" + std::to_string(k) + "]"));
    return out;
  }
  std::vector<double> numbers(const json& j, const std::string& key) const {
    std::vector<double> out;
    for (std::size_t k = 0; k < array(j, key).size(); ++k)
      out.push_back(number(j[k], key + "[" + std::to_string(k) + "]"));
    return out;
  }

 private:
  std::string file_;
};

// A block: its id, name, density and model, then the parameters that model declares
// (materials/bond_model.hpp), each a number in the model's range; unknown keys are errors.
BlockMaterial read_block(const Checker& ck, const json& j, std::size_t k) {
  const std::string where = "blocks[" + std::to_string(k) + "]";
  ck.object(j, where);
  BlockMaterial b;
  if (const json* m = ck.optional(j, "model")) {
    b.model = ck.string(*m, where + ".model");
    if (!material_registry().contains(b.model)) ck.fail(where + ".model", material_registry().unknown_message(b.model));
  }
  const MaterialDefinition& law = material_registry().get(b.model);
  std::vector<std::string> allowed = {"id", "name", "model", "density"};
  for (const auto& p : law.parameters) allowed.push_back(p.name);
  // A parameter of another model (poisson_ratio under model: pmb): say which model has it and what
  // this one does instead, rather than only "unknown key".
  for (const auto& item : j.items()) {
    if (std::find(allowed.begin(), allowed.end(), item.key()) != allowed.end()) continue;
    for (const std::string& other : material_registry().keys())
      for (const auto& p : material_registry().get(other).parameters)
        if (p.name == item.key())
          ck.fail(where + "." + item.key(), "model '" + b.model + "' has no parameter '" + item.key() + "' (" + b.model +
                                                ": " + law.doc + "); model '" + other + "' has it (" + p.doc +
                                                "): set model: " + other);
  }
  ck.known_keys(j, where, allowed);
  const std::int64_t id = ck.integer(ck.required(j, "id", where + ".id"), where + ".id", 1, 1 << 30);
  if (id != static_cast<std::int64_t>(k) + 1)
    ck.fail(where + ".id", "must be " + std::to_string(k + 1) + " (blocks are numbered 1, 2, … in order), got " +
                               std::to_string(id));
  b.name = ck.string(ck.required(j, "name", where + ".name"), where + ".name");
  b.density = ck.positive(ck.required(j, "density", where + ".density"), where + ".density");
  for (const auto& p : law.parameters) {
    const std::string key = where + "." + p.name;
    const json* value = p.required ? &ck.required(j, p.name, key) : ck.optional(j, p.name);
    if (!p.choices.empty()) {  // a text parameter: one of its names, the first by default
      b.choices[p.name] = p.choices.front();
      if (!value || value->is_null()) continue;
      const std::string name = ck.string(*value, key);
      if (std::find(p.choices.begin(), p.choices.end(), name) == p.choices.end())
        ck.fail(key, "unknown name '" + name + "'" + closest(name, p.choices) + "; known: " + joined(p.choices));
      b.choices[p.name] = name;
      continue;
    }
    if (!value || (!p.required && value->is_null())) continue;
    const double v = ck.number(*value, key);
    if (p.lower_inclusive) {
      if (!(v >= p.lower && v < p.upper))
        ck.fail(key, "must be at least " + show(json(p.lower)) +
                         (std::isinf(p.upper) ? std::string() : " and below " + show(json(p.upper))) + ", got " +
                         show(*value));
      b.parameters[p.name] = v;
      continue;
    }
    if (p.lower == 0.0 && std::isinf(p.upper)) {
      b.parameters[p.name] = ck.positive(*value, key);
      continue;
    }
    if (!(v > p.lower && v < p.upper))
      ck.fail(key, "must be between " + show(json(p.lower)) + " and " + show(json(p.upper)) + " (exclusive), got " +
                       show(*value) + (p.bounds_reason.empty() ? std::string() : ": " + p.bounds_reason));
    b.parameters[p.name] = v;
  }
  if (law.check)
    if (const ParameterProblem problem = law.check(b); !problem.key.empty())
      ck.fail(where + "." + problem.key, problem.message);
  return b;
}

BoundaryCondition read_boundary(const Checker& ck, const json& j, std::size_t k) {
  const std::string where = "boundary_conditions[" + std::to_string(k) + "]";
  ck.object(j, where);
  ck.known_keys(j, where, case_keys().at("boundary_conditions[]"));
  BoundaryCondition bc;
  bc.set = ck.string(ck.required(j, "set", where + ".set"), where + ".set");
  bc.kind = ck.string(ck.required(j, "kind", where + ".kind"), where + ".kind");
  if (bc.kind != "displacement" && bc.kind != "velocity" && bc.kind != "body_force")
    ck.fail(where + ".kind", "unknown kind '" + bc.kind + "'; known: displacement, velocity, body_force");
  bc.component = static_cast<int>(ck.integer(ck.required(j, "component", where + ".component"), where + ".component", 0, 2));
  bc.times = ck.numbers(ck.required(j, "times", where + ".times"), where + ".times");
  bc.values = ck.numbers(ck.required(j, "values", where + ".values"), where + ".values");
  if (bc.times.empty()) ck.fail(where + ".times", "needs at least one time");
  if (bc.values.size() != bc.times.size())
    ck.fail(where + ".values", "has " + std::to_string(bc.values.size()) + " entries but times has " +
                                   std::to_string(bc.times.size()));
  for (std::size_t i = 1; i < bc.times.size(); ++i)
    if (!(bc.times[i] > bc.times[i - 1]))
      ck.fail(where + ".times", "must be strictly increasing (entry " + std::to_string(i) + ")");
  return bc;
}

InitialCondition read_initial(const Checker& ck, const json& j, std::size_t k) {
  const std::string where = "initial_conditions[" + std::to_string(k) + "]";
  ck.object(j, where);
  ck.known_keys(j, where, case_keys().at("initial_conditions[]"));
  InitialCondition ic;
  ic.set = ck.string(ck.required(j, "set", where + ".set"), where + ".set");
  ic.kind = ck.string(ck.required(j, "kind", where + ".kind"), where + ".kind");
  if (ic.kind != "displacement" && ic.kind != "velocity")
    ck.fail(where + ".kind", "unknown kind '" + ic.kind + "'; known: velocity, displacement");
  ic.component = static_cast<int>(ck.integer(ck.required(j, "component", where + ".component"), where + ".component", 0, 2));
  ic.value = ck.number(ck.required(j, "value", where + ".value"), where + ".value");
  if (const json* g = ck.optional(j, "gradient"); g && !g->is_null()) {
    ic.gradient = ck.number(*g, where + ".gradient");
    if (ic.gradient != 0.0 && ic.kind != "displacement")
      ck.fail(where + ".gradient", "is only allowed for kind displacement (a uniform pre-strain)");
  }
  return ic;
}

std::array<double, 3> read_vector(const Checker& ck, const json& j, const std::string& key) {
  const std::vector<double> v = ck.numbers(j, key);
  if (v.size() != 3) ck.fail(key, "must have 3 components, got " + std::to_string(v.size()));
  return {v[0], v[1], v[2]};
}

// A direction given as any non-zero vector, returned as a unit vector.
std::array<double, 3> read_direction(const Checker& ck, const json& j, const std::string& key) {
  std::array<double, 3> v = read_vector(ck, j, key);
  const double norm = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(norm > 0.0) || !std::isfinite(norm)) ck.fail(key, "must be a non-zero vector");
  for (double& c : v) c /= norm;
  return v;
}

// A pre-crack segment (core/cracks.hpp): two distinct points.
CrackSegment read_crack(const Checker& ck, const json& j, std::size_t k) {
  const std::string where = "cracks[" + std::to_string(k) + "]";
  ck.object(j, where);
  ck.known_keys(j, where, case_keys().at("cracks[]"));
  CrackSegment crack;
  crack.from = read_vector(ck, ck.required(j, "from", where + ".from"), where + ".from");
  crack.to = read_vector(ck, ck.required(j, "to", where + ".to"), where + ".to");
  if (crack.from[0] == crack.to[0] && crack.from[1] == crack.to[1])
    ck.fail(where, "from and to are the same point in the xy plane");
  return crack;
}

IndenterSettings read_indenter(const Checker& ck, const json& j, std::size_t k) {
  const std::string where = "indenters[" + std::to_string(k) + "]";
  ck.object(j, where);
  ck.known_keys(j, where, case_keys().at("indenters[]"));
  IndenterSettings ind;
  ind.name = ck.string(ck.required(j, "name", where + ".name"), where + ".name");
  const bool name_ok = !ind.name.empty() && !std::isdigit(static_cast<unsigned char>(ind.name[0])) &&
                       std::all_of(ind.name.begin(), ind.name.end(),
                                   [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; });
  if (!name_ok) ck.fail(where + ".name", "must be letters, digits and '_', not starting with a digit (it names history.csv columns)");
  ind.shape = ck.string(ck.required(j, "shape", where + ".shape"), where + ".shape");
  if (!indenter_shape_registry().contains(ind.shape))
    ck.fail(where + ".shape", indenter_shape_registry().unknown_message(ind.shape));
  ind.centre = read_vector(ck, ck.required(j, "centre", where + ".centre"), where + ".centre");
  if (const json* v = ck.optional(j, "velocity"); v && !v->is_null()) ind.velocity = read_vector(ck, *v, where + ".velocity");
  ind.stiffness = ck.positive(ck.required(j, "stiffness", where + ".stiffness"), where + ".stiffness");
  if (ind.shape == "plane") {
    ind.normal = read_direction(ck, ck.required(j, "normal", where + ".normal"), where + ".normal");
  } else {
    ind.radius = ck.positive(ck.required(j, "radius", where + ".radius"), where + ".radius");
    if (ind.shape == "cylinder") {
      ind.axis = kDefaultCylinderAxis;
      if (const json* a = ck.optional(j, "axis"); a && !a->is_null()) ind.axis = read_direction(ck, *a, where + ".axis");
    }
  }
  return ind;
}

// The text of a bound in a message: 0, 0.5, 1 (not json's 0.0).
std::string bound_text(double bound) {
  std::ostringstream out;
  out << bound;
  return out.str();
}

// One value of a settings section, checked against its declaration (io/settings_table.hpp) and
// stored in the field the declaration points to.
void read_setting(const Checker& ck, const json& v, const Setting& s, const std::string& key) {
  const std::string why = s.why.empty() ? std::string() : " (" + s.why + ")";
  auto number = [&](const json& j) {
    const double x = ck.number(j, key);
    if (s.minimum && s.maximum) {
      if (x < *s.minimum || x > *s.maximum)
        ck.fail(key, "must be between " + bound_text(*s.minimum) + " and " + bound_text(*s.maximum) + why + ", got " + show(j));
      return x;
    }
    if (s.above && !(x > *s.above)) ck.fail(key, "must be > " + bound_text(*s.above) + ", got " + show(j));
    if (s.minimum && x < *s.minimum) ck.fail(key, "must be ≥ " + bound_text(*s.minimum) + ", got " + show(j));
    if (s.below && !(x < *s.below)) ck.fail(key, "must be below " + bound_text(*s.below) + why + ", got " + show(j));
    return x;
  };
  auto name = [&](const std::string& given, const std::string& where, const std::string& did_you_mean) {
    if (std::find(s.choices.begin(), s.choices.end(), given) == s.choices.end())
      ck.fail(where, "unknown " + s.noun + " '" + given + "'" + did_you_mean + "; known: " + joined(s.choices));
  };
  std::visit(
      [&](auto field) {
        using Field = decltype(field);
        if constexpr (std::is_same_v<Field, double*> || std::is_same_v<Field, std::optional<double>*>) {
          *field = number(v);
        } else if constexpr (std::is_same_v<Field, int*>) {
          *field = static_cast<int>(ck.integer(v, key, s.lowest, s.highest));
        } else if constexpr (std::is_same_v<Field, std::int64_t*> || std::is_same_v<Field, std::optional<std::int64_t>*>) {
          *field = ck.integer(v, key, s.lowest, s.highest);
        } else if constexpr (std::is_same_v<Field, bool*>) {
          if (!v.is_boolean()) ck.fail(key, "must be true or false, got " + show(v));
          *field = v.get<bool>();
        } else if constexpr (std::is_same_v<Field, std::string*>) {
          *field = ck.string(v, key);
          name(*field, key, "");
        } else if constexpr (std::is_same_v<Field, std::vector<std::string>*>) {
          std::vector<std::string>& list = *field;
          list = ck.strings(v, key);
          if (s.choices.empty()) return;
          for (std::size_t k = 0; k < list.size(); ++k) {
            name(list[k], key + "[" + std::to_string(k) + "]", closest(list[k], s.choices));
            if (std::count(list.begin(), list.end(), list[k]) > 1) ck.fail(key, "'" + list[k] + "' is listed twice");
          }
        } else {  // RuleOrNumber: a number makes the rule "fixed"
          static_assert(std::is_same_v<Field, RuleOrNumber>);
          if (!v.is_string()) {
            *field.rule = "fixed";
            *field.number = number(v);
            return;
          }
          *field.rule = v.get<std::string>();
          if (std::find(s.choices.begin(), s.choices.end(), *field.rule) == s.choices.end())
            ck.fail(key, "unknown " + s.noun + " '" + *field.rule + "'; known: " + joined(s.choices) + ", or a number [" +
                             s.unit + "]");
        }
      },
      s.field);
}

// A settings section (io/case_settings.cpp): an object of its keys only, each one absent (the
// default), or null where its type is optional, or a value in its range.
void read_settings(const Checker& ck, const json& j, const SettingsSection& section) {
  ck.object(j, section.name);
  std::vector<std::string> keys;
  for (const Setting& s : section.settings) keys.push_back(s.key);
  ck.known_keys(j, section.name, keys);
  for (const Setting& s : section.settings) {
    const std::string key = section.name + "." + s.key;
    const json* v = s.required ? &ck.required(j, s.key, key) : ck.optional(j, s.key);
    if (!v) continue;
    const bool optional_type = std::holds_alternative<std::optional<double>*>(s.field) ||
                               std::holds_alternative<std::optional<std::int64_t>*>(s.field);
    if (v->is_null() && (optional_type || s.null_is_default)) continue;
    read_setting(ck, *v, s, key);
  }
}

// dt_initial, dt_min and dt_max of adaptive, quasi_static or implicit, against one another;
// initial_too false: dt_initial is not checked (quasi_static lowers one above dt_max to it).
void check_step_limits(const Checker& ck, const std::string& section, const std::optional<double>& dt_initial,
                       const std::optional<double>& dt_min, const std::optional<double>& dt_max, bool initial_too) {
  if (dt_min && dt_max && *dt_min > *dt_max) ck.fail(section + ".dt_min", "is larger than " + section + ".dt_max");
  if (!initial_too) return;
  if (dt_initial && dt_max && *dt_initial > *dt_max)
    ck.fail(section + ".dt_initial", "is larger than " + section + ".dt_max");
  if (dt_initial && dt_min && *dt_initial < *dt_min)
    ck.fail(section + ".dt_initial", "is smaller than " + section + ".dt_min");
}

// output_dir, which must stay inside the run folder (the directory of case.json): pdsolve writes
// frames, history.csv, run.log and checkpoint.bin there and deletes the old frames and checkpoint
// it finds, so "/abs/path", "../../x" or a symbolic link out of the folder would let a case file
// write and delete files anywhere its user may (issue 36, item 3). Checked lexically first (an
// absolute path, or one whose normal form starts with ".."), then the folders of it that exist:
// their real path, links followed, must still lie in the real path of the run folder.
std::filesystem::path confined_output_dir(const Checker& ck, const std::filesystem::path& dir, const std::string& text) {
  namespace fs = std::filesystem;
  const fs::path given(text);
  const std::string advice = "; give a folder inside the directory of case.json, such as \".\" or \"out\"";
  if (given.has_root_name() || given.has_root_directory())
    ck.fail("output_dir", "'" + text + "' is an absolute path; pdsolve writes only inside the run folder" + advice);
  const fs::path normal = given.lexically_normal();
  if (!normal.empty() && *normal.begin() == "..")
    ck.fail("output_dir", "'" + text + "' leaves the run folder (the directory of case.json)" + advice);
  std::error_code folder_error, target_error;
  // "case.json" in the working folder has an empty dir: both sides start from "." then, or the
  // target of a folder not made yet stays relative ("out") and compares as outside ("/run/out").
  const fs::path base = dir.empty() ? fs::path(".") : dir;
  const fs::path folder = fs::weakly_canonical(base, folder_error);
  const fs::path target = fs::weakly_canonical(base / normal, target_error);
  // Not checkable (a folder that cannot be searched): writing there fails later with its own message.
  if (!folder_error && !target_error) {
    const fs::path inside = target.lexically_relative(folder);
    if (inside.empty() || *inside.begin() == "..")
      ck.fail("output_dir", "'" + text + "' leads through a symbolic link to " + target.string() +
                                ", outside the run folder " + folder.string() + advice);
  }
  return dir / text;
}

}  // namespace

const std::map<std::string, std::vector<std::string>>& case_keys() {
  static const std::map<std::string, std::vector<std::string>> keys = [] {
    std::map<std::string, std::vector<std::string>> k = {
        {"", {"format_version", "case", "title", "source", "nodes_file", "output_dir", "dimension", "analysis",
              "thickness", "grid_spacing", "horizon", "blocks", "no_fail_sets", "node_sets", "boundary_conditions",
              "initial_conditions", "damping", "time", "adaptive", "quasi_static", "implicit", "mixed", "output",
              "figures", "partial_volume", "surface_correction", "breaking_order", "contact", "indenters", "cracks"}},
        {"boundary_conditions[]", {"set", "kind", "component", "times", "values"}},
        {"initial_conditions[]", {"set", "kind", "component", "value", "gradient"}},
        {"cracks[]", {"from", "to"}},
        {"indenters[]", {"name", "shape", "radius", "centre", "velocity", "normal", "axis", "stiffness"}},
    };
    Case c;  // the tables point into it; only their keys are taken
    for (const SettingsSection& section : settings_sections(c))
      for (const Setting& s : section.settings) k[section.name].push_back(s.key);
    return k;
  }();
  return keys;
}

Case parse_case(const std::string& text, const std::filesystem::path& path) {
  const std::string file = path.string();
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {  // parse_error, and out_of_range for numbers like 1e800 (fuzzing)
    throw Error(file + ": not valid JSON: " + e.what());
  }
  const Checker ck(file);
  if (!root.is_object()) throw Error(file + ": the top level must be a JSON object");
  ck.known_keys(root, "", case_keys().at(""));
  Case c;
  c.file = path;
  // The settings sections (io/case_settings.cpp), each read at its place in the order of the checks.
  const std::vector<SettingsSection> sections = settings_sections(c);
  auto read_section = [&](const std::string& name) {
    const SettingsSection& section =
        *std::find_if(sections.begin(), sections.end(), [&](const SettingsSection& s) { return s.name == name; });
    const json* j = section.required ? &ck.required(root, name, name) : ck.optional(root, name);
    if (section.required || (j && !j->is_null())) read_settings(ck, *j, section);
  };
  const std::int64_t version = ck.integer(ck.required(root, "format_version", "format_version"), "format_version", 0, 1 << 30);
  if (version != kCaseFormatVersion)
    ck.fail("format_version", "is " + std::to_string(version) + "; this solver reads version " +
                                  std::to_string(kCaseFormatVersion));
  if (const json* j = ck.optional(root, "case")) c.name = ck.string(*j, "case");
  if (const json* j = ck.optional(root, "title")) c.title = ck.string(*j, "title");
  if (const json* j = ck.optional(root, "source")) c.source = ck.string(*j, "source");
  const std::filesystem::path dir = path.parent_path();
  const std::string nodes_file = ck.string(ck.required(root, "nodes_file", "nodes_file"), "nodes_file");
  if (nodes_file.empty()) ck.fail("nodes_file", "must not be empty");
  c.nodes_file = dir / nodes_file;
  std::string output_dir = kDefaultOutputDir;
  if (const json* j = ck.optional(root, "output_dir")) output_dir = ck.string(*j, "output_dir");
  c.output_dir = confined_output_dir(ck, dir, output_dir);

  c.dimension = static_cast<int>(ck.integer(ck.required(root, "dimension", "dimension"), "dimension", 2, 3));
  c.analysis = ck.string(ck.required(root, "analysis", "analysis"), "analysis");
  if (!analysis_registry().contains(c.analysis)) ck.fail("analysis", analysis_registry().unknown_message(c.analysis));
  if (analysis_dimension(c.analysis) != c.dimension)
    ck.fail("analysis", "'" + c.analysis + "' does not fit dimension " + std::to_string(c.dimension));
  if (c.dimension == 2) {
    c.thickness = ck.positive(ck.required(root, "thickness", "thickness"), "thickness");
  } else if (const json* j = ck.optional(root, "thickness"); j && !j->is_null()) {
    c.thickness = ck.positive(*j, "thickness");  // allowed but unused in 3D
  }
  c.grid_spacing = ck.positive(ck.required(root, "grid_spacing", "grid_spacing"), "grid_spacing");
  c.horizon = ck.positive(ck.required(root, "horizon", "horizon"), "horizon");

  if (const json* j = ck.optional(root, "partial_volume")) {
    c.partial_volume = ck.string(*j, "partial_volume");
    if (!partial_volume_registry().contains(c.partial_volume))
      ck.fail("partial_volume", partial_volume_registry().unknown_message(c.partial_volume));
  }
  if (const json* j = ck.optional(root, "surface_correction")) {
    c.surface_correction = ck.string(*j, "surface_correction");
    if (!surface_correction_registry().contains(c.surface_correction))
      ck.fail("surface_correction", surface_correction_registry().unknown_message(c.surface_correction));
  }

  const json& blocks = ck.array(ck.required(root, "blocks", "blocks"), "blocks");
  if (blocks.empty()) ck.fail("blocks", "needs at least one block");
  for (std::size_t k = 0; k < blocks.size(); ++k) c.blocks.push_back(read_block(ck, blocks[k], k));
  // A bond joins two blocks, so its law must be one both ends share.
  for (std::size_t k = 1; k < c.blocks.size(); ++k)
    if (c.blocks[k].model != c.blocks[0].model)
      ck.fail("blocks[" + std::to_string(k) + "].model",
              "is '" + c.blocks[k].model + "' but blocks[0] is '" + c.blocks[0].model +
                  "': every block of a case must use the same material model");
  // A text parameter (LPS's influence function) is one per case: m_i sums over both blocks of a bond.
  for (std::size_t k = 1; k < c.blocks.size(); ++k)
    for (const auto& [name, value] : c.blocks[k].choices)
      if (value != c.blocks[0].choice(name, value))
        ck.fail("blocks[" + std::to_string(k) + "]." + name, "is '" + value + "' but blocks[0] has '" +
                                                               c.blocks[0].choice(name, value) +
                                                               "': every block of a case must use the same " + name);

  if (const json* j = ck.optional(root, "breaking_order")) {
    c.breaking_order = ck.string(*j, "breaking_order");
    if (c.breaking_order != "thesis" && c.breaking_order != "lammps")
      ck.fail("breaking_order", "unknown order '" + c.breaking_order + "'; known: thesis, lammps");
    if (c.breaking_order == "lammps" && c.blocks[0].model != "pmb")
      ck.fail("breaking_order", "lammps is LAMMPS peri/pmb's order, for model pmb; blocks use '" + c.blocks[0].model + "'");
  }
  if (const json* j = ck.optional(root, "no_fail_sets")) c.no_fail_sets = ck.strings(*j, "no_fail_sets");
  if (const json* j = ck.optional(root, "node_sets")) c.node_sets = ck.strings(*j, "node_sets");
  if (const json* j = ck.optional(root, "boundary_conditions"))
    for (std::size_t k = 0; k < ck.array(*j, "boundary_conditions").size(); ++k)
      c.boundary_conditions.push_back(read_boundary(ck, (*j)[k], k));
  if (const json* j = ck.optional(root, "initial_conditions"))
    for (std::size_t k = 0; k < ck.array(*j, "initial_conditions").size(); ++k)
      c.initial_conditions.push_back(read_initial(ck, (*j)[k], k));
  if (const json* j = ck.optional(root, "cracks"))
    for (std::size_t k = 0; k < ck.array(*j, "cracks").size(); ++k) c.cracks.push_back(read_crack(ck, (*j)[k], k));
  if (const json* j = ck.optional(root, "damping")) c.damping = ck.non_negative(*j, "damping");
  read_section("contact");
  if (const json* j = ck.optional(root, "indenters"))
    for (std::size_t k = 0; k < ck.array(*j, "indenters").size(); ++k) {
      c.indenters.push_back(read_indenter(ck, (*j)[k], k));
      for (std::size_t q = 0; q < k; ++q)
        if (c.indenters[q].name == c.indenters[k].name)
          ck.fail("indenters[" + std::to_string(k) + "].name", "'" + c.indenters[k].name + "' is used twice");
    }

  read_section("time");
  read_section("adaptive");
  check_step_limits(ck, "adaptive", c.adaptive.dt_initial, c.adaptive.dt_min, c.adaptive.dt_max, true);
  read_section("quasi_static");
  check_step_limits(ck, "quasi_static", c.quasi_static.dt_initial, c.quasi_static.dt_min, c.quasi_static.dt_max, false);
  read_section("implicit");
  check_step_limits(ck, "implicit", c.implicit.dt_initial, c.implicit.dt_min, c.implicit.dt_max, true);
  read_section("mixed");
  if (const json* j = ck.optional(root, "figures"); j && !j->is_null()) ck.object(*j, "figures");    // postprocess only

  read_section("output");
  if (c.output.every_time.has_value() == c.output.every_steps.has_value())
    ck.fail("output", "exactly one of every_time and every_steps must be set (not null)");
  for (const auto& [key, names] : {std::pair{"output.reactions", &c.output.reactions}, std::pair{"output.probes", &c.output.probes}})
    for (const auto& name : *names)
      if (std::find(c.node_sets.begin(), c.node_sets.end(), name) == c.node_sets.end())
        ck.fail(key, "'" + name + "' is not in node_sets");
  return c;
}

Case read_case(const std::filesystem::path& path) {
  return parse_case(read_whole_file(path, "the case file"), path);
}

}  // namespace pd
