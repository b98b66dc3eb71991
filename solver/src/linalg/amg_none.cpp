// AMG in a build without hypre (PD_HYPRE off, see linalg/amg.hpp): nothing to set up; asking for it
// is refused with the way to get it. quasi_static's auto never asks (available() is false).
#include "core/error.hpp"
#include "linalg/amg.hpp"

namespace pd {

struct AmgPreconditioner::Impl {};

AmgPreconditioner::AmgPreconditioner() = default;
AmgPreconditioner::~AmgPreconditioner() = default;
bool AmgPreconditioner::available() { return false; }
std::uint64_t AmgPreconditioner::estimated_bytes(std::uint64_t, std::uint64_t) { return 0; }
void AmgPreconditioner::set_up(const SparseMatrix&, int, const std::vector<std::uint8_t>&) {
  throw Error("quasi_static.preconditioner: amg needs hypre's BoomerAMG, which this pdsolve was built without: "
              "install libhypre-dev (pipeline/install-deps.sh) and rebuild (cmake finds it: PD_HYPRE), or use "
              "preconditioner: block_jacobi (or auto)");
}
bool AmgPreconditioner::ready() const { return false; }
void AmgPreconditioner::apply(const std::vector<double>& r, std::vector<double>& z) const { z = r; }
int AmgPreconditioner::levels() const { return 0; }
double AmgPreconditioner::operator_complexity() const { return 0.0; }
void AmgPreconditioner::clear() {}

}  // namespace pd
