// Inputs that once crashed a reader under the fuzzers (solver/fuzz/regressions/<target>/) must now
// give a pd::Error or a valid result: any other exception fails here, and the sanitizer build
// catches memory errors. Add every new crasher that `make fuzz` finds to that folder.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>

#include "../fuzz/checkpoint_seal.hpp"
#include "core/error.hpp"
#include "io/case_reader.hpp"
#include "io/checkpoint.hpp"
#include "io/node_file.hpp"
#include "io/vtu.hpp"

namespace fs = std::filesystem;

TEST(FuzzRegressions, EveryStoredInputIsHandled) {
  const std::map<std::string, std::function<void(const std::string&, const std::string&)>> readers{
      {"pd_fuzz_node_file", [](const std::string& t, const std::string& f) { pd::parse_node_file(t, f); }},
      {"pd_fuzz_vtu", [](const std::string& t, const std::string& f) { pd::parse_vtu(t, f); }},
      {"pd_fuzz_case", [](const std::string& t, const std::string& f) { pd::parse_case(t, f); }},
      // As pd_fuzz_checkpoint reads it: as stored, then sealed (fuzz/checkpoint_seal.hpp).
      {"pd_fuzz_checkpoint",
       [](const std::string& t, const std::string& f) {
         try {
           pd::parse_checkpoint(t, f);
         } catch (const pd::Error&) {
         }
         pd::parse_checkpoint(pd_fuzz::sealed_checkpoint(t), f);
       }},
  };
  const fs::path root = fs::path(PD_SOURCE_DIR) / "fuzz" / "regressions";
  int inputs = 0;
  for (const auto& [target, read] : readers) {
    if (!fs::is_directory(root / target)) continue;
    for (const auto& entry : fs::directory_iterator(root / target)) {
      std::ifstream in(entry.path(), std::ios::binary);
      const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      ++inputs;
      try {
        read(text, entry.path().string());
      } catch (const pd::Error&) {
        // a clear message for bad input: what we want
      } catch (const std::exception& e) {
        ADD_FAILURE() << entry.path() << ": " << typeid(e).name() << ": " << e.what();
      }
    }
  }
  EXPECT_GE(inputs, 2) << "no regression inputs found under " << root;
}
