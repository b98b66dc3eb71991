// libFuzzer target: arbitrary bytes through the generic VTU reader (frames too: lines, CellData)
// must give a pd::Error or a grid whose arrays have the sizes the reader checked.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.hpp"
#include "io/vtu.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const pd::VtuGrid g = pd::parse_vtu(text, "fuzz.vtu");
    // Callers index point arrays by point and cell arrays by cell: the sizes must hold.
    for (const auto& a : g.point_data)
      if (a.tuples() != g.points_count()) __builtin_trap();
    for (const auto& a : g.cell_data)
      if (a.tuples() != g.cells_count()) __builtin_trap();
  } catch (const pd::Error&) {
  }
  return 0;
}
