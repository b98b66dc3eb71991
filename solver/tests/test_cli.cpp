// The command line: --help documents every option main.cpp accepts, --version says how the binary
// was built, and a bad option is a usage error (exit code 2).
#include <gtest/gtest.h>
#include <unistd.h>

#include <omp.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <utility>

namespace fs = std::filesystem;

namespace {

struct Result {
  int code = -1;
  std::string out;
};

// env: assignments for the shell before the command, e.g. "OMP_NUM_THREADS=4".
Result run_solver(const std::string& args, const std::string& env = "") {
  const fs::path log = fs::temp_directory_path() / ("pd_test_cli_" + std::to_string(::getpid()) + ".txt");
  const std::string command = env + " " + std::string(PDSOLVE_PATH) + " " + args + " > " + log.string() + " 2>&1";
  const int status = std::system(command.c_str());
  std::ifstream in(log);
  Result r{WIFEXITED(status) ? WEXITSTATUS(status) : -1,
           {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()}};
  fs::remove(log);
  return r;
}

// Every option main.cpp compares an argument with, e.g. `arg == "--threads"`.
std::set<std::string> options_in_source() {
  std::ifstream in(fs::path(PD_SOURCE_DIR) / "src" / "main.cpp");
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  static const std::regex option(R"(arg == "(-{1,2}[A-Za-z][A-Za-z0-9-]*)\")");
  std::set<std::string> out;
  for (std::sregex_iterator it(text.begin(), text.end(), option), end; it != end; ++it) out.insert((*it)[1]);
  return out;
}

bool built_with_address_sanitizer() {
#if defined(__SANITIZE_ADDRESS__)
  return true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  return true;
#endif
#endif
  return false;
}

}  // namespace

TEST(CommandLine, HelpDocumentsEveryOption) {
  const Result r = run_solver("--help");
  EXPECT_EQ(r.code, 0);
  const auto options = options_in_source();
  ASSERT_GE(options.size(), 6u) << "the scan of main.cpp found too few options; did its style change?";
  for (const auto& o : options) {
    if (o == "-h") continue;  // the short form of --help
    // Documented on a line of its own: two spaces, the option, then its description.
    EXPECT_NE(r.out.find("\n  " + o + " "), std::string::npos) << o << " is not documented in --help:\n" << r.out;
  }
  EXPECT_NE(r.out.find("Exit codes"), std::string::npos);
}

TEST(CommandLine, VersionNamesTheBuild) {
  const Result r = run_solver("--version");
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out.rfind(std::string("pdsolve ") + PD_VERSION + "\n", 0), 0u) << r.out;
  for (const char* line : {"\nbuild type: ", "\ncompiler: ", "\nflags: ", "\nOpenMP: ", "\nsanitizers: "})
    EXPECT_NE(r.out.find(line), std::string::npos) << "missing '" << line + 1 << "' in:\n" << r.out;
  // The sanitizer line tells the truth about this very build (the test shares pdsolve's flags).
  const std::string want = built_with_address_sanitizer() ? "\nsanitizers: address,undefined\n" : "\nsanitizers: off\n";
  EXPECT_NE(r.out.find(want), std::string::npos) << r.out;
}

TEST(CommandLine, BadOptionsAreUsageErrors) {
  Result r = run_solver("--thread 4 case.json");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("unknown option '--thread'"), std::string::npos) << r.out;
  r = run_solver("case.json --threads zero");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--threads needs an integer"), std::string::npos) << r.out;
  r = run_solver("");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("no case file given"), std::string::npos) << r.out;
}

// 100000 OpenMP threads crashed the runtime (exit 139, issue 17, item 9): a usage error now.
TEST(CommandLine, TooManyThreadsIsAUsageError) {
  const Result r = run_solver("case.json --threads 100000");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--threads 100000: at most "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" threads here (max(64, 4 × the processors))"), std::string::npos) << r.out;
}

// OMP_NUM_THREADS is held to the same limit as --threads (issue 36, item 10): before, 100000 there
// crashed the OpenMP runtime (exit 139), 20000 ran for minutes and 65–5000 were taken. Every entry
// of a nested list counts, and text the runtime would ignore is refused, naming the variable, before
// any work: a case.json that does not exist is never reached (exit 2, not 1).
TEST(CommandLine, TooManyOrBadThreadsInOmpNumThreadsIsAUsageError) {
  const std::string limit = std::to_string(std::max(64, 4 * omp_get_num_procs()));
  const std::string over = std::to_string(std::max(64, 4 * omp_get_num_procs()) + 1);
  for (const std::string value : {std::string("100000"), over, "4," + over}) {
    const Result r = run_solver("missing.json", "OMP_NUM_THREADS=" + value);
    EXPECT_EQ(r.code, 2) << value << ": " << r.out;
    EXPECT_NE(r.out.find("pdsolve: OMP_NUM_THREADS=" + value + ": at most " + limit +
                         " threads here (max(64, 4 × the processors)); unset it, or give --threads N, which overrides it"),
              std::string::npos) << r.out;
  }
  for (const auto& [value, entry] : {std::pair<std::string, std::string>{"many", "many"}, {"0", "0"}, {"4,", ""},
                                     {"4,two", "two"}, {"-3", "-3"}, {"2.5", "2.5"}}) {
    const Result r = run_solver("missing.json", "OMP_NUM_THREADS='" + value + "'");
    EXPECT_EQ(r.code, 2) << value << ": " << r.out;
    EXPECT_NE(r.out.find("pdsolve: OMP_NUM_THREADS=" + value + ": needs a thread count ≥ 1, or a list of them for "
                         "nested levels (such as 4,2); got '" + entry + "'"),
              std::string::npos) << r.out;
  }
  // Within the limit, as a list, empty, or overridden by --threads: on to the case file (exit 1, missing).
  for (const auto& [env, args] : {std::pair<std::string, std::string>{"OMP_NUM_THREADS=" + limit, ""},
                                  {"OMP_NUM_THREADS=4,2", ""}, {"OMP_NUM_THREADS=", ""},
                                  {"OMP_NUM_THREADS=100000", " --threads 2"}}) {
    const Result r = run_solver("missing.json" + args, env);
    EXPECT_EQ(r.code, 1) << env << args << ": " << r.out;
    EXPECT_NE(r.out.find("missing.json"), std::string::npos) << r.out;
  }
}
