// The free-dof map and the CSR product (see sparse_matrix.hpp).
#include "linalg/sparse_matrix.hpp"

namespace pd {

FreeDofs FreeDofs::of(std::size_t n, int dimension, const std::array<std::vector<std::uint8_t>, 3>& fixed) {
  FreeDofs dofs;
  dofs.index.assign(3 * n, -1);
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < dimension; ++d)
      if (!fixed[static_cast<std::size_t>(d)][i]) {
        dofs.index[3 * i + static_cast<std::size_t>(d)] = static_cast<std::int64_t>(dofs.node.size());
        dofs.node.push_back(static_cast<std::int64_t>(i));
        dofs.component.push_back(static_cast<std::uint8_t>(d));
      }
  return dofs;
}

void FreeDofs::gather(const Vec3Array& a, std::vector<double>& out) const {
  out.resize(size());
  for (std::size_t k = 0; k < size(); ++k) out[k] = a[component[k]][static_cast<std::size_t>(node[k])];
}

void FreeDofs::scatter(const std::vector<double>& in, Vec3Array& a) const {
  for (std::size_t k = 0; k < size(); ++k) a[component[k]][static_cast<std::size_t>(node[k])] = in[k];
}

void SparseMatrix::multiply(const std::vector<double>& x, std::vector<double>& y) const {
  y.resize(static_cast<std::size_t>(rows));
#pragma omp parallel for schedule(static)
  for (std::int64_t r = 0; r < rows; ++r) {
    double sum = 0.0;
    for (std::int64_t k = row_start[static_cast<std::size_t>(r)]; k < row_start[static_cast<std::size_t>(r) + 1]; ++k)
      sum += value[static_cast<std::size_t>(k)] * x[static_cast<std::size_t>(column[static_cast<std::size_t>(k)])];
    y[static_cast<std::size_t>(r)] = sum;
  }
}

}  // namespace pd
