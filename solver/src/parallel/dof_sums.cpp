// Exact sums over the free dofs (see dof_sums.hpp).
#include "parallel/dof_sums.hpp"

namespace pd {

namespace {

// Σ_k term(k) for k < n into sum, exactly: threads sum their own ranges and merge (exact, so the
// bits do not depend on the thread count). Small sums stay on one thread.
template <class Term>
void add_terms(std::size_t n, ExactSum& sum, Term term) {
  const auto count = static_cast<std::int64_t>(n);
#pragma omp parallel if (count >= 32768)
  {
    ExactSum mine;
#pragma omp for schedule(static)
    for (std::int64_t k = 0; k < count; ++k) mine.add(term(static_cast<std::size_t>(k)));
#pragma omp critical(pd_dof_sums)
    sum.add(mine);
  }
}

}  // namespace

void DofSums::setup(const Decomposed* d, const FreeDofs&) { d_ = d; }

std::vector<double> DofSums::sums(const std::vector<const std::vector<double>*>& arrays) const {
  std::vector<ExactSum> exact(arrays.size());
  for (std::size_t a = 0; a < arrays.size(); ++a) {
    const std::vector<double>& terms = *arrays[a];
    add_terms(terms.size(), exact[a], [&](std::size_t k) { return terms[k]; });
  }
  if (d_) d_->reduce(exact.data(), static_cast<int>(exact.size()));
  std::vector<double> result(arrays.size());
  for (std::size_t a = 0; a < arrays.size(); ++a) result[a] = exact[a].value();
  return result;
}

double DofSums::dot(const std::vector<double>& a, const std::vector<double>& b) const {
  ExactSum exact;
  add_terms(a.size(), exact, [&](std::size_t k) { return a[k] * b[k]; });
  if (d_) d_->reduce(&exact, 1);
  return exact.value();
}

}  // namespace pd
