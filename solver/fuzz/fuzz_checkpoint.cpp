// libFuzzer target: arbitrary bytes as checkpoint.bin must give a pd::Error or a checkpoint whose
// arrays have the lengths the reader checked, never a crash, a hang, another exception, a
// sanitizer report or an allocation sized by a count in the file. Each input is read twice: as
// it is (header, size and checksum checks) and sealed (checkpoint_seal.hpp: the payload parser).
// The reader needs no case or model; pdsolve's checks against them come after it (run.cpp).
#include <cstddef>
#include <cstdint>
#include <string>

#include "checkpoint_seal.hpp"
#include "core/error.hpp"
#include "io/checkpoint.hpp"

namespace {

void read(const std::string& bytes) {
  try {
    const pd::Checkpoint c = pd::parse_checkpoint(bytes, "fuzz/checkpoint.bin");
    // What the reader promises run.cpp, which indexes these arrays by node; a broken promise is a bug.
    const std::size_t n = c.nodes;
    for (const auto* a : {&c.state.u, &c.state.v, &c.state.f})
      for (const auto& comp : *a)
        if (comp.size() != n) __builtin_trap();
    if (c.state.w.size() != n || c.integrator.empty()) __builtin_trap();
    for (const auto& comp : c.contact_u_build)
      if (comp.size() != c.contact_u_build[0].size() || (!comp.empty() && comp.size() != n)) __builtin_trap();
  } catch (const pd::Error&) {
    // the expected outcome for bad input; any other exception escapes and libFuzzer reports it
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  read(bytes);
  read(pd_fuzz::sealed_checkpoint(bytes));
  return 0;
}
