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
  for (const std::string& model : material_registry().keys())
    for (const MaterialParameter& p : material_registry().get(model).parameters) {
      nlohmann::json& key = keys[p.name];
      if (key.is_null()) {
        key = {{"type", "number"}, {"unit", p.unit}, {p.lower_inclusive ? "minimum" : "above", p.lower},
               {"models", nlohmann::json::array()}};
        if (p.required) key["required"] = true;
        else key["default"] = nullptr;
        if (std::isfinite(p.upper)) key["below"] = p.upper;
        if (!p.required) key["note"] = p.doc;
      }
      key["models"].push_back(model);
    }
  return keys;
}

}  // namespace pd
