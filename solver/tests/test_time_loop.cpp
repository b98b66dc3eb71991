// The time loop through pdsolve: frames land exactly on k·every_time for both integrators, an
// unstable Verlet run is stopped with a message naming the step and the cause and writes no
// non-finite frame, dt "exact" runs, and a bad adaptive value is an input error.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "io/node_file.hpp"
#include "io/vtu.hpp"
#include "files.hpp"
#include "lattice.hpp"

namespace fs = std::filesystem;

namespace {

fs::path temp_dir(const std::string& name) { return pdtest::temp_dir("time_" + name); }
using pdtest::slurp;

int run_solver(const fs::path& dir) {
  const std::string command = std::string(PDSOLVE_PATH) + " " + (dir / "case.json").string() + " --threads 1 --quiet > " +
                              (dir / "log.txt").string() + " 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A free 2D plate, 14 × 10 nodes, set vibrating by an initial velocity of one edge row.
void write_case(const fs::path& dir, const std::string& time, const std::string& extra = "",
                const std::string& every = "3e-7") {
  pd::Nodes nodes = pdtest::cubic_lattice(14, 10, 1, 1e-3, 2, 1e-3);
  pd::NodeSet edge{"edge", std::vector<std::uint8_t>(nodes.size(), 0)};
  for (std::size_t i = 0; i < nodes.size(); ++i) edge.member[i] = nodes.x[0][i] < 0.5e-3;
  nodes.sets = {edge};
  pd::write_node_file(dir / "nodes.vtu", nodes);
  std::ofstream(dir / "case.json") << R"({
    "format_version": 1, "case": "vibe", "nodes_file": "nodes.vtu", "output_dir": "out",
    "dimension": 2, "analysis": "plane_stress", "thickness": 0.001, "grid_spacing": 0.001, "horizon": 0.003015,
    "blocks": [{"id": 1, "name": "plate", "model": "pmb", "density": 2440.0, "youngs_modulus": 7.2e10,
                "fracture_energy": null}],
    "node_sets": ["edge"],
    "initial_conditions": [{"set": "edge", "kind": "velocity", "component": 0, "value": 1.0}],
    "time": )" + time + extra + R"(,
    "output": {"every_time": )" + every + R"(, "every_steps": null, "history_every": 1}
  })";
}

std::vector<double> frame_times(const fs::path& out) {
  const std::string pvd = slurp(out / "frames.pvd");
  const std::regex dataset("<DataSet timestep=\"([^\"]+)\"");
  std::vector<double> times;
  for (auto it = std::sregex_iterator(pvd.begin(), pvd.end(), dataset); it != std::sregex_iterator(); ++it)
    times.push_back(std::stod((*it)[1]));
  return times;
}

}  // namespace

TEST(TimeLoop, FramesLandExactlyOnOutputTimesForBothIntegrators) {
  for (const std::string integrator : {"verlet", "adaptive"}) {
    const fs::path dir = temp_dir("land_" + integrator);
    // 3e-7 s is not a multiple of the stable step (≈ 1.1e-7 × 0.8), so every frame needs a short step.
    write_case(dir, R"({"end": 3e-6, "integrator": ")" + integrator + R"(", "dt": "stable", "safety_factor": 0.8})",
               integrator == "adaptive" ? R"(, "adaptive": {"tol": 1e-3, "kd": 20, "p": 3.0, "phi": 0.5})" : "");
    ASSERT_EQ(run_solver(dir), 0) << slurp(dir / "log.txt");
    const std::vector<double> times = frame_times(dir / "out");
    ASSERT_EQ(times.size(), 11u) << integrator;
    for (std::size_t k = 0; k < times.size(); ++k) {
      const pd::VtuGrid g = pd::read_vtu(dir / "out" / "frames" / ("frame_" + std::string(6 - std::to_string(k).size(), '0') + std::to_string(k) + ".vtu"));
      const double t = pd::values_of<double>(*g.find(g.field_data, "TIME"))[0];
      // exactly k·every_time as the loop computes it (the .pvd text rounds to its own digits)
      EXPECT_EQ(t, static_cast<double>(k) * 3e-7) << integrator << " frame " << k;
    }
    const std::string log = slurp(dir / "out" / "run.log");
    EXPECT_NE(log.find("force evaluations"), std::string::npos) << log;
  }
}

TEST(TimeLoop, VerletAboveTheExactLimitIsStoppedWithoutNonFiniteFrames) {
  const fs::path dir = temp_dir("blowup");
  write_case(dir, R"({"end": 2e-5, "integrator": "verlet", "dt": "exact", "safety_factor": 1.5})", "", "1e-6");
  ASSERT_EQ(run_solver(dir), 3) << slurp(dir / "log.txt");
  const std::string message = slurp(dir / "log.txt");
  EXPECT_TRUE(std::regex_search(message, std::regex("step [0-9]+"))) << message;
  EXPECT_NE(message.find("above the stability limit"), std::string::npos) << message;
  EXPECT_NE(message.find("1.5 × the exact stability limit"), std::string::npos) << message;
  // Every frame written is finite.
  for (const auto& entry : fs::directory_iterator(dir / "out" / "frames")) {
    const pd::VtuGrid g = pd::read_vtu(entry.path());
    for (const char* name : {"displacement", "velocity"})
      for (double x : pd::values_as_double(*g.find(g.point_data, name))) ASSERT_TRUE(std::isfinite(x)) << entry.path();
  }
  EXPECT_EQ(slurp(dir / "out" / "history.csv").find("nan"), std::string::npos);
  EXPECT_EQ(slurp(dir / "out" / "history.csv").find("inf"), std::string::npos);
}

// Just above the exact limit the energy grows ×1.5 a step only once it is large; the energy balance
// (run/watches.hpp EnergyBalanceWatch) sees the run hold more than it was given long before (issue
// 17, item 12). The frames written after the energy passed 2 × what was given are removed, so the
// last frame kept is no faster than the initial 1 m/s.
TEST(TimeLoop, EnergyBalanceStopsARunJustAboveTheExactLimitAndKeepsOnlySaneFrames) {
  const fs::path dir = temp_dir("balance");
  write_case(dir, R"({"end": 1e-3, "integrator": "verlet", "dt": "exact", "safety_factor": 1.02})", "", "1e-6");
  ASSERT_EQ(run_solver(dir), 3) << slurp(dir / "log.txt");
  const std::string log = slurp(dir / "out" / "run.log");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(log, m, std::regex("error: after step ([0-9]+) \\(t = [^)]*\\) the kinetic, strain and "
                                                   "contact energy plus the damping work are [0-9.e+-]+ J, ([0-9.]+) × the "
                                                   "energy the run was given")))
      << log;
  EXPECT_LT(std::stoi(m[1]), 21);  // the ×1.5-a-step watch needs 20 steps of growth: it has not fired
  EXPECT_GT(std::stod(m[2]), 10.0);
  EXPECT_NE(log.find("this one passed 2 × at step 7): the energy balance is broken"), std::string::npos) << log;
  EXPECT_NE(log.find("is 1.02 × the exact stability limit"), std::string::npos) << log;
  EXPECT_NE(log.find("the time step is above the stability limit"), std::string::npos) << log;
  EXPECT_NE(log.find("removed 2 frame(s) written from step 7 on, while the energy held was more than 2 × the energy given"),
            std::string::npos)
      << log;
  for (const auto& entry : fs::directory_iterator(dir / "out" / "frames")) {
    const pd::VtuGrid g = pd::read_vtu(entry.path());
    const std::vector<double> v = pd::values_as_double(*g.find(g.point_data, "velocity"));
    for (std::size_t i = 0; i + 2 < v.size(); i += 3)
      ASSERT_LE(std::sqrt(v[i] * v[i] + v[i + 1] * v[i + 1] + v[i + 2] * v[i + 2]), 1.0 + 1e-6) << entry.path();
  }
}

// Never on a sound run: the same plate at 0.95 of the exact limit, 200 steps, holds its energy.
TEST(TimeLoop, ExactTimeStepRunsStablyAtSafetyFactor095) {
  const fs::path dir = temp_dir("exact");
  write_case(dir, R"({"end": 1e-5, "integrator": "verlet", "dt": "exact", "safety_factor": 0.95})", "", "1e-6");
  ASSERT_EQ(run_solver(dir), 0) << slurp(dir / "log.txt");
  const std::string log = slurp(dir / "out" / "run.log");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(log, m, std::regex("exact limit [0-9.e-]+ s = ([0-9.]+) × eq. 2.5"))) << log;
  EXPECT_GT(std::stod(m[1]), 1.4);  // a 2D plate, m = 3: well above eq. 2.5 (periodic lattice: 1.67)
  EXPECT_LT(std::stod(m[1]), 1.9);
}

// A step the integrator cannot take (here adaptive at 10 × eq. 2.5 with no room to shorten it) goes
// through the loop's one failure exit: exit 3, the error on stderr and in run.log, and the closing
// line "stopped" with the state before it kept (frame 0, nothing removed).
TEST(TimeLoop, AStepThatFailsStopsTheRunAndKeepsTheLastAcceptedState) {
  const fs::path dir = temp_dir("step_failed");
  write_case(dir, R"({"end": 1e-5, "integrator": "adaptive"})",
             R"(, "adaptive": {"tol": 1e-3, "dt_initial": 1e-6, "dt_min": 1e-6, "dt_max": 1e-6})");
  ASSERT_EQ(run_solver(dir), 3) << slurp(dir / "log.txt");
  const std::string message = slurp(dir / "log.txt");
  EXPECT_NE(message.find("pdsolve: error: step 1: the adaptive step did not converge at dt_min"), std::string::npos)
      << message;
  EXPECT_NE(message.find("; stopped, the last accepted state is kept"), std::string::npos) << message;
  const std::string log = slurp(dir / "out" / "run.log");
  EXPECT_NE(log.find("pdsolve: error: step 1: "), std::string::npos) << log;
  EXPECT_NE(log.find("stopped: 0 steps to t = 0 s"), std::string::npos) << log;
  EXPECT_EQ(log.find("removed "), std::string::npos) << log;
  EXPECT_EQ(frame_times(dir / "out"), std::vector<double>{0.0});
}

TEST(TimeLoop, BadAdaptiveValueIsAnInputError) {
  const fs::path dir = temp_dir("bad");
  write_case(dir, R"({"end": 1e-6, "integrator": "adaptive"})", R"(, "adaptive": {"tol": 1e-3, "phi": 0.2})");
  EXPECT_EQ(run_solver(dir), 1);
  EXPECT_NE(slurp(dir / "log.txt").find("adaptive.phi: must be between 0.5 and 1, got 0.2"), std::string::npos)
      << slurp(dir / "log.txt");
  EXPECT_FALSE(fs::exists(dir / "out" / "frames.pvd"));
}

TEST(TimeLoop, AnIndenterTooStiffForTheStepIsReportedOnceWithItsDepth) {
  // A plane indenter driven at 500 m/s into the plate's x = 0 edge (it starts 0.5 mm away): its
  // stiffness 2K·h joins the stable step (forces/indenter.hpp). With K = 1e21 N/m⁵ the step (0.8 of
  // eq. 2.5) is guaranteed only to a depth of about 0.06 mm, and the edge, resisting with about
  // ρ·c·v ≈ 6 GPa, lets the indenter in deeper; with K = 1e15 the allowed depth is metres, also
  // at 0.8 of the exact limit (above eq. 2.5, where eq. 2.5 alone would allow no indenter at all).
  struct Run {
    double stiffness;
    const char* dt;
    bool warns;
  };
  for (const Run run : {Run{1e21, "stable", true}, Run{1e15, "stable", false}, Run{1e15, "exact", false}}) {
    const fs::path dir = temp_dir(std::string("indenter_") + (run.warns ? "stiff" : "soft") + "_" + run.dt);
    char indenter[400];
    std::snprintf(indenter, sizeof indenter,
                  R"(, "indenters": [{"name": "punch", "shape": "plane", "centre": [-0.0005, 0, 0],
                      "normal": [1, 0, 0], "velocity": [500, 0, 0], "stiffness": %g}])",
                  run.stiffness);
    write_case(dir, std::string(R"({"end": 5e-6, "integrator": "verlet", "dt": ")") + run.dt +
                        R"(", "safety_factor": 0.8})",
               indenter, "1e-6");
    const int status = run_solver(dir);
    const std::string log = slurp(dir / "out" / "run.log");
    std::smatch stable;
    ASSERT_TRUE(std::regex_search(log, stable, std::regex("indenter 'punch': dt stays stable while no node is deeper "
                                                          "than ([0-9.e+-]+) m")))
        << log;
    const double stable_depth = std::stod(stable[1]);
    const std::regex warning("warning: step [0-9]+ \\(t = [0-9.e+-]+ s\\): indenter 'punch' is [0-9.e+-]+ m deep at "
                             "node [0-9]+.*guaranteed stable only below [0-9.e+-]+ s < dt");
    const auto warnings = std::distance(std::sregex_iterator(log.begin(), log.end(), warning), std::sregex_iterator());
    if (run.warns) {
      EXPECT_EQ(warnings, 1) << log;  // once, however long it stays too deep
      EXPECT_LT(stable_depth, 2e-4) << log;
      EXPECT_GT(stable_depth, 1e-5) << log;
    } else {
      EXPECT_EQ(status, 0) << log;
      EXPECT_EQ(warnings, 0) << log;
      EXPECT_GT(stable_depth, 2e-3) << log;  // deeper than the indenter gets (2 mm)
    }
  }
}

TEST(TimeLoop, ASoftRoundIndenterIsStableAtAnyDepthItCanReach) {
  // A depth bound past the radius means nothing for a sphere or a disk (issue 16: "no node deeper than
  // 1.007 m" for a 1.5 mm disk): run.log says the step holds at any depth and gives both numbers.
  const fs::path dir = temp_dir("indenter_round_soft");
  write_case(dir, R"({"end": 2e-6, "integrator": "verlet", "dt": "stable", "safety_factor": 0.8})",
             R"(, "indenters": [{"name": "ball", "shape": "cylinder", "radius": 0.0015, "axis": [0, 0, 1], "centre": [-0.002, 0, 0],
                 "velocity": [500, 0, 0], "stiffness": 1e15}])",
             "1e-6");
  ASSERT_EQ(run_solver(dir), 0) << slurp(dir / "log.txt");
  const std::string log = slurp(dir / "out" / "run.log");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(log, m, std::regex("indenter 'ball': dt stays stable at any depth \\(its stiffness 2K·h "
                                                   "with eq. 2.5 allows ([0-9.e+-]+) m, more than its radius 0.0015 m\\)")))
      << log;
  EXPECT_GE(std::stod(m[1]), 0.0015);
  EXPECT_EQ(log.find("no node is deeper"), std::string::npos) << log;
}

TEST(TimeLoop, AdaptiveWithTheExactRuleReusesTheExactLimitForItsDefaultDtMax) {
  // time.dt "exact" already ran the Lanczos estimate; the adaptive default Δt_max
  // min(eq. 2.5, 0.9·Δt_exact/(2φ)) takes that value instead of estimating it again.
  const fs::path dir = temp_dir("adaptive_exact");
  write_case(dir, R"({"end": 1e-6, "integrator": "adaptive", "dt": "exact", "safety_factor": 0.5})",
             R"(, "adaptive": {"tol": 1e-3, "kd": 20, "p": 3.0, "phi": 1.0})");
  ASSERT_EQ(run_solver(dir), 0) << slurp(dir / "log.txt");
  const std::string log = slurp(dir / "out" / "run.log");
  std::smatch exact, stable, dt_max;
  ASSERT_TRUE(std::regex_search(log, exact, std::regex("exact limit ([0-9.e+-]+) s = ([0-9.e+-]+) × eq. 2.5"))) << log;
  ASSERT_TRUE(std::regex_search(log, dt_max, std::regex("dt_max ([0-9.e+-]+) s \\(default: eq. 2.5 or 0.9 × the "
                                                        "contraction limit, from the exact limit above\\)")))
      << log;
  const double dt_exact = std::stod(exact[1]), eq25 = dt_exact / std::stod(exact[2]);
  EXPECT_NEAR(std::stod(dt_max[1]), std::min(eq25, 0.9 * dt_exact / 2.0), 1e-5 * std::stod(dt_max[1])) << log;
  EXPECT_EQ(log.find("eigenvalue estimate"), std::string::npos) << log;
}

// A case.json whose output_dir leaves its folder (issue 36, item 3) is refused by pdsolve with exit
// code 1 before any file is written: before, an absolute path, "../x" or "sub/../../x" received the
// frames, history.csv and run.log, and a link out of the folder did the same.
TEST(TimeLoop, AnOutputDirOutsideTheRunFolderIsRefusedBeforeAnyFileIsWritten) {
  const fs::path dir = temp_dir("output_dir_outside");
  const fs::path run = dir / "run";
  fs::create_directories(run);
  write_case(run, R"({"end": 3e-7, "integrator": "verlet", "dt": "stable", "safety_factor": 0.8})");
  const std::string text = slurp(run / "case.json"), given = "\"output_dir\": \"out\"";
  ASSERT_NE(text.find(given), std::string::npos);
  fs::create_directories(dir / "elsewhere");
  fs::create_directory_symlink(dir / "elsewhere", run / "away");
  const fs::path absolute = dir / "absolute";
  for (const std::string& output_dir : {absolute.string(), std::string("../up"), std::string("sub/../../up"),
                                        std::string("away/out")}) {
    std::string changed = text;
    changed.replace(changed.find(given), given.size(), "\"output_dir\": \"" + output_dir + "\"");
    std::ofstream(run / "case.json") << changed;
    EXPECT_EQ(run_solver(run), 1) << output_dir << ": " << slurp(run / "log.txt");
    EXPECT_NE(slurp(run / "log.txt").find((run / "case.json").string() + ": output_dir: '" + output_dir + "' "),
              std::string::npos) << slurp(run / "log.txt");
    EXPECT_FALSE(fs::exists(absolute)) << output_dir;
    EXPECT_FALSE(fs::exists(dir / "up")) << output_dir;
    EXPECT_TRUE(fs::is_empty(dir / "elsewhere")) << output_dir;
  }
  // The folder holds what it held: the case, the nodes, the link and the solver's log only.
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(run)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"away", "case.json", "log.txt", "nodes.vtu"}));
  fs::remove_all(dir);
}
