// libFuzzer target: arbitrary bytes as case.json must give a pd::Error or a checked Case, never
// a crash, a hang, another exception (nlohmann's own included) or a sanitizer report.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.hpp"
#include "io/case_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const pd::Case c = pd::parse_case(text, "fuzz/case.json");
    if (!(c.horizon > 0.0) || !(c.time.end > 0.0) || c.blocks.empty()) __builtin_trap();
  } catch (const pd::Error&) {
  }
  return 0;
}
