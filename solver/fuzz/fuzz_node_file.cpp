// libFuzzer target: arbitrary bytes as a node file (VTU reader + node-file checks) must give a
// pd::Error or a valid node set, never a crash, a hang, another exception or a sanitizer report.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.hpp"
#include "io/node_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const pd::Nodes nodes = pd::parse_node_file(text, "fuzz.vtu");
    // What the reader promises the solver (pipeline/formats.md §2); a broken promise is a bug.
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (!(nodes.volume[i] > 0.0) || nodes.block[i] < 1) __builtin_trap();
  } catch (const pd::Error&) {
    // the expected outcome for bad input; any other exception escapes and libFuzzer reports it
  }
  return 0;
}
