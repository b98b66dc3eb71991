// The material keys of a case.json block for pdsolve --describe (io/describe.hpp).
#include <nlohmann/json.hpp>

#include "core/material.hpp"
#include "io/describe.hpp"

namespace pd {

// MERGE NOTE: hard-coded for model "pmb" to match case_reader.cpp read_block(); once materials are
// a registry (solver/src/materials/<name>/), build this from the registered models instead (the
// model's choices from the registry's keys(), each model's own keys and ranges).
nlohmann::json describe_material_keys() {
  const BlockMaterial b{};
  return {
      {"model", {{"type", "string"}, {"default", b.model}, {"choices", {"pmb"}}}},
      {"density", {{"type", "number"}, {"required", true}, {"above", 0.0}, {"unit", "kg/m³"}}},
      {"youngs_modulus", {{"type", "number"}, {"required", true}, {"above", 0.0}, {"unit", "Pa"}}},
      {"fracture_energy",
       {{"type", "number"}, {"default", nullptr}, {"above", 0.0}, {"unit", "J/m²"}, {"note", "null: unbreakable"}}},
  };
}

}  // namespace pd
