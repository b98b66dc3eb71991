// pdsolve --describe: every case.json key the solver reads, with its type, default, choices and
// range, as JSON (pipeline/formats.md §6), so that tests/pipeline/test_describe.py can hold
// pipeline/schema.py to it.
#pragma once
#include <nlohmann/json.hpp>

namespace pd {

// {"describe_version": 1, "keys": {"time.dt": {...}, "blocks[].density": {...}, ...},
//  "registries": {"integrator": [...], ...}}. Throws pd::Error if the description and the
// reader's key lists (io/case_reader.hpp case_keys) disagree.
nlohmann::json describe_case();

// The keys of one entry of case.json "blocks" that belong to its material (all but id and name),
// each described as in describe_case(). For now the keys read_block() reads for model "pmb",
// written out by hand: the material registry (solver/src/materials/) will provide them per model.
nlohmann::json describe_material_keys();

}  // namespace pd
