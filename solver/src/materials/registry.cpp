// The material registry: every folder under materials/ registers its model here, through the
// generated register_all_materials() (solver/CMakeLists.txt writes it from the folder names).
#include "materials/bond_model.hpp"

namespace pd {

void register_all_materials(MaterialRegistry& registry);  // generated: material_index.cpp

const MaterialRegistry& material_registry() {
  static const MaterialRegistry registry = [] {
    MaterialRegistry r("material model");
    register_all_materials(r);
    return r;
  }();
  return registry;
}

MaterialTable make_material_table(const std::vector<BlockMaterial>& blocks, const std::string& analysis, double horizon,
                                  double thickness) {
  const MaterialDefinition& law = material_registry().get(blocks.empty() ? std::string("pmb") : blocks[0].model);
  std::vector<PairConstants> per_block;
  for (const auto& b : blocks) per_block.push_back(law.constants(b, analysis, horizon, thickness));
  return make_pair_table(std::move(per_block));
}

}  // namespace pd
