// One key of a case.json settings section, declared once: its type (the type of the field it is
// read into), default (that field's value in a fresh struct of core/case.hpp), range, choices and
// unit. The reader checks a value against it (io/case_reader.cpp), case_keys() lists it and
// pdsolve --describe prints it (io/describe.cpp), so that the three cannot disagree, as a
// material's parameters are declared once in its folder (materials/bond_model.hpp).
// The sections' tables are in io/case_settings.cpp.
#pragma once
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace pd {

// time.dt: a rule by name or a number of seconds (then the rule is "fixed").
struct RuleOrNumber {
  std::string* rule;
  double* number;
};

struct Setting {
  // Where the reader stores the value; its type is the key's type in case.json: a number
  // (optional: null or absent leaves it empty), an integer, true/false, a name, a list of names.
  using Field = std::variant<double*, std::optional<double>*, int*, std::int64_t*, std::optional<std::int64_t>*, bool*,
                             std::string*, std::vector<std::string>*, RuleOrNumber>;

  Setting(std::string key, Field field) : key(std::move(key)), field(field) {}

  std::string key;  // its name inside the section
  Field field;

  // A number's range in --describe's words: > above, ≥ minimum, < below, ≤ maximum (absent: no
  // such bound); `why` says why in the reader's message, e.g. "a relative error".
  std::optional<double> above, minimum, below, maximum;
  std::string why;
  // An integer's range, both ends included (the largest int64: no maximum).
  std::int64_t lowest = std::numeric_limits<std::int64_t>::min();
  std::int64_t highest = std::numeric_limits<std::int64_t>::max();
  // A name or a list of names: the names allowed, and what one is called in the reader's message
  // ("unknown value 'x'; known: ...", "unknown integrator 'x'; ...").
  std::vector<std::string> choices;
  std::string noun = "value";
  std::string unit;  // SI, for --describe
  std::string note;  // for --describe: what the type and range do not say
  bool required = false;  // else absent: the default
  // null reads as absent (the default) for a key that is not optional in type (contact.skin).
  bool null_is_default = false;

  Setting& in_unit(std::string u) {
    unit = std::move(u);
    return *this;
  }
  Setting& with_note(std::string n) {
    note = std::move(n);
    return *this;
  }
  Setting& called(std::string n) {
    noun = std::move(n);
    return *this;
  }
  Setting& needed() {
    required = true;
    return *this;
  }
  Setting& null_means_default() {
    null_is_default = true;
    return *this;
  }
};

// The builders a section's table is written with, named after the range they declare.
inline Setting positive(std::string key, double& field) {
  Setting s(std::move(key), &field);
  s.above = 0.0;
  return s;
}
inline Setting positive(std::string key, std::optional<double>& field) {
  Setting s(std::move(key), &field);
  s.above = 0.0;
  return s;
}
inline Setting non_negative(std::string key, double& field) {
  Setting s(std::move(key), &field);
  s.minimum = 0.0;
  return s;
}
// 0 < value < 1.
inline Setting fraction(std::string key, double& field, std::string why) {
  Setting s(std::move(key), &field);
  s.above = 0.0;
  s.below = 1.0;
  s.why = std::move(why);
  return s;
}
// minimum ≤ value ≤ maximum.
inline Setting between(std::string key, double& field, double minimum, double maximum, std::string why = {}) {
  Setting s(std::move(key), &field);
  s.minimum = minimum;
  s.maximum = maximum;
  s.why = std::move(why);
  return s;
}
template <class Integer>  // int, std::int64_t or std::optional<std::int64_t>
Setting integer(std::string key, Integer& field, std::int64_t lowest,
                std::int64_t highest = std::numeric_limits<std::int64_t>::max()) {
  Setting s(std::move(key), &field);
  s.lowest = lowest;
  s.highest = highest;
  return s;
}
inline Setting flag(std::string key, bool& field) { return Setting(std::move(key), &field); }
inline Setting choice(std::string key, std::string& field, std::vector<std::string> choices) {
  Setting s(std::move(key), &field);
  s.choices = std::move(choices);
  return s;
}
// A list of names; `choices` empty: any names.
inline Setting names(std::string key, std::vector<std::string>& field, std::vector<std::string> choices = {}) {
  Setting s(std::move(key), &field);
  s.choices = std::move(choices);
  return s;
}
// A rule by name or a positive number (time.dt).
inline Setting rule_or_positive(std::string key, std::string& rule, double& number, std::vector<std::string> rules) {
  Setting s{std::move(key), RuleOrNumber{&rule, &number}};
  s.above = 0.0;
  s.choices = std::move(rules);
  s.noun = "rule";
  return s;
}

// A settings section of case.json ("quasi_static", ...) and its keys, in the order the reader
// reads them and case_keys() lists them (which breaks a tie of "did you mean").
struct SettingsSection {
  std::string name;
  bool required = false;  // time and output must be there; the others default to {}
  std::string note;       // for --describe
  std::vector<Setting> settings;
};

}  // namespace pd
