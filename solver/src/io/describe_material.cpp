// The material keys of a case.json block for pdsolve --describe (io/describe.hpp), from the
// material registry: the model choices are its keys, each model's keys its declared parameters
// (materials/bond_model.hpp), so the reader, --describe and the registry cannot drift apart.
#include <cmath>
#include <nlohmann/json.hpp>

#include "core/material.hpp"
#include "io/describe.hpp"
#include "materials/bond_model.hpp"

namespace pd {

nlohmann::json describe_material_keys() {
  const BlockMaterial b{};
  nlohmann::json keys = {
      {"model", {{"type", "string"}, {"default", b.model}, {"choices", material_registry().keys()}}},
      {"density", {{"type", "number"}, {"required", true}, {"above", 0.0}, {"unit", "kg/m³"}}},
  };
  // A key is required only if every model requires it (a model without the key does not):
  // youngs_modulus is, poisson_ratio (LPS only) is not, and says which models read it.
  for (const std::string& model : material_registry().keys())
    for (const MaterialParameter& p : material_registry().get(model).parameters) {
      nlohmann::json& key = keys[p.name];
      if (key.is_null()) {
        if (!p.choices.empty()) {
          key = {{"type", "string"}, {"choices", p.choices}, {"default", nullptr}, {"models", nlohmann::json::array()}};
          key["note"] = p.doc + " (default " + p.choices.front() + ")";
        } else {
          key = {{"type", "number"}, {"unit", p.unit}, {p.lower_inclusive ? "minimum" : "above", p.lower}, {"models", nlohmann::json::array()}};
          if (std::isfinite(p.upper)) key["below"] = p.upper;
          key["note"] = p.doc;
        }
      }
      key["models"].push_back(model);
    }
  for (auto& [name, key] : keys.items()) {
    if (!key.contains("models")) continue;
    bool everywhere = key["models"].size() == material_registry().keys().size();
    for (const auto& model : key["models"])
      for (const MaterialParameter& p : material_registry().get(model.get<std::string>()).parameters)
        if (p.name == name && !p.required) everywhere = false;
    if (everywhere) {
      key["required"] = true;
      key.erase("note");
    } else if (!key.contains("default")) {
      key["default"] = nullptr;
    }
  }
  return keys;
}

}  // namespace pd
