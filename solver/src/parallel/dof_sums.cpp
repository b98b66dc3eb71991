// Sums over the free dofs in global dof order (see dof_sums.hpp).
#include "parallel/dof_sums.hpp"

#include "linalg/pcg.hpp"
#include "parallel/local_model.hpp"

namespace pd {

void DofSums::setup(const Decomposed* d, const FreeDofs& dofs) {
  d_ = d;
  nodes_ = 0;
  node_of_dof_.clear(), merged_mask_.clear();
  if (!d_) return;
  nodes_ = d_->piece().size();
  // Which components of each owned node are dofs, as a bit mask per node, on rank 0 once.
  std::vector<double> mask(nodes_, 0.0);
  for (std::size_t k = 0; k < dofs.size(); ++k) {
    const auto i = static_cast<std::size_t>(dofs.node[k]);
    mask[i] = static_cast<double>(static_cast<unsigned>(mask[i]) | (1u << dofs.component[k]));
    node_of_dof_.push_back(i);
  }
  component_of_dof_ = dofs.component;
  const std::vector<double> merged = d_->gather(mask);
  merged_mask_.assign(merged.begin(), merged.end());
}

std::vector<std::vector<double>> DofSums::in_global_order(const std::vector<const std::vector<double>*>& arrays) const {
  const std::size_t m = arrays.size(), width = 3 * m;
  // Per local node, per array, its 3 components (0 where not a dof: rank 0 reads only the mask's).
  std::vector<double> values(width * nodes_, 0.0);
  for (std::size_t k = 0; k < node_of_dof_.size(); ++k)
    for (std::size_t a = 0; a < m; ++a) values[width * node_of_dof_[k] + 3 * a + component_of_dof_[k]] = (*arrays[a])[k];
  const std::vector<double> all = d_->gather(values, static_cast<int>(width));
  std::vector<std::vector<double>> out(d_->rank() == 0 ? m : 0);
  if (d_->rank() != 0) return out;
  for (std::size_t g = 0; g < merged_mask_.size(); ++g)
    for (std::size_t c = 0; c < 3; ++c)
      if (merged_mask_[g] & (1u << c))
        for (std::size_t a = 0; a < m; ++a) out[a].push_back(all[width * g + 3 * a + c]);
  return out;
}

std::vector<double> DofSums::sums(const std::vector<const std::vector<double>*>& arrays) const {
  std::vector<double> result(arrays.size(), 0.0);
  if (!d_) {
    for (std::size_t a = 0; a < arrays.size(); ++a)
      for (double term : *arrays[a]) result[a] += term;  // the serial loops' order: dof order
    return result;
  }
  const auto global = in_global_order(arrays);
  for (std::size_t a = 0; a < global.size(); ++a)
    for (double term : global[a]) result[a] += term;
  d_->broadcast(result);
  return result;
}

double DofSums::dot(const std::vector<double>& a, const std::vector<double>& b) const {
  if (!d_) return fixed_order_dot(a, b);
  std::vector<double> products(a.size());
  for (std::size_t k = 0; k < a.size(); ++k) products[k] = a[k] * b[k];
  const auto global = in_global_order({&products});
  std::vector<double> result{global.empty() ? 0.0 : fixed_order_sum(global[0])};
  d_->broadcast(result);
  return result[0];
}

}  // namespace pd
