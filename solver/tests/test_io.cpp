// File readers: the node file round-trips and bad node files / case files are rejected with
// messages that name the file and what (or which key) is wrong.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "core/error.hpp"
#include "io/case_reader.hpp"
#include "io/node_file.hpp"
#include "io/vtu.hpp"
#include "files.hpp"
#include "lattice.hpp"

namespace fs = std::filesystem;

namespace {

fs::path temp_dir(const std::string& name) { return pdtest::temp_dir("io_" + name); }
using pdtest::slurp;

void spit(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

pd::Nodes sample_nodes() {
  pd::Nodes n = pdtest::cubic_lattice(4, 3, 1, 0.5, 2, 0.01);
  n.block[5] = 2;
  n.sets.push_back({"left", {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}});
  return n;
}

// Expects read_node_file to throw with every fragment in the message.
void expect_node_error(const fs::path& p, const std::vector<std::string>& fragments) {
  try {
    pd::read_node_file(p);
    FAIL() << "no error for " << p;
  } catch (const pd::Error& e) {
    for (const auto& f : fragments) EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
  }
}

const char* const kCase = R"({
  "format_version": 1, "case": "t", "title": "x", "source": "t.yaml", "nodes_file": "nodes.vtu",
  "output_dir": ".", "dimension": 2, "analysis": "plane_stress", "thickness": 0.001,
  "grid_spacing": 0.0005, "horizon": 0.0015075,
  "blocks": [{"id": 1, "name": "plate", "model": "pmb", "density": 1200.0, "youngs_modulus": 3.0e9,
              "fracture_energy": null}],
  "no_fail_sets": [], "node_sets": ["clamped"],
  "boundary_conditions": [{"set": "clamped", "kind": "displacement", "component": 2, "times": [0.0], "values": [0.0]}],
  "initial_conditions": [{"set": "centre", "kind": "velocity", "component": 2, "value": 5.0}],
  "damping": 200.0,
  "time": {"end": 0.01, "integrator": "verlet", "dt": "stable", "safety_factor": 0.8, "max_steps": 10000000},
  "adaptive": {"tol": 1e-3, "kd": 20, "p": 3.0, "phi": 1.0, "dt_initial": null, "dt_min": null, "dt_max": null},
  "output": {"every_time": 1e-4, "every_steps": null, "history_every": 1},
  "figures": {"times": null, "displacement_component": 2}
})";

// Replaces the first occurrence of `from` in kCase and expects an error naming file and key.
void expect_case_error(const std::string& from, const std::string& to, const std::vector<std::string>& fragments) {
  std::string text = kCase;
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  try {
    pd::parse_case(text, "out/x/case.json");
    FAIL() << "no error after replacing " << from << " by " << to;
  } catch (const pd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("out/x/case.json: "), std::string::npos) << e.what();
    for (const auto& f : fragments) EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(NodeFile, RoundTrip) {
  const fs::path dir = temp_dir("roundtrip");
  const pd::Nodes a = sample_nodes();
  pd::write_node_file(dir / "nodes.vtu", a);
  const pd::Nodes b = pd::read_node_file(dir / "nodes.vtu");
  EXPECT_EQ(b.dimension, 2);
  EXPECT_EQ(b.grid_spacing, a.grid_spacing);
  EXPECT_EQ(b.x, a.x);
  EXPECT_EQ(b.volume, a.volume);
  EXPECT_EQ(b.block, a.block);
  ASSERT_EQ(b.sets.size(), 1u);
  EXPECT_EQ(b.sets[0].name, "left");
  EXPECT_EQ(b.sets[0].member, a.sets[0].member);
  EXPECT_FALSE(fs::exists(dir / "nodes.vtu.part"));  // written through a temporary name
  fs::remove_all(dir);
}

TEST(NodeFile, RejectsTruncatedFile) {
  const fs::path dir = temp_dir("truncated");
  pd::write_node_file(dir / "good.vtu", sample_nodes());
  const std::string text = slurp(dir / "good.vtu");
  spit(dir / "cut.vtu", text.substr(0, text.size() - 200));
  expect_node_error(dir / "cut.vtu", {(dir / "cut.vtu").string() + ": ", "truncated"});
  spit(dir / "cut2.vtu", text.substr(0, text.find("<AppendedData") - 10));
  expect_node_error(dir / "cut2.vtu", {(dir / "cut2.vtu").string() + ": "});
  spit(dir / "empty.vtu", "");
  expect_node_error(dir / "empty.vtu", {"empty"});
  fs::remove_all(dir);
}

TEST(NodeFile, RejectsWrongHeaderAndEncoding) {
  const fs::path dir = temp_dir("header");
  pd::write_node_file(dir / "good.vtu", sample_nodes());
  const std::string text = slurp(dir / "good.vtu");
  auto variant = [&](const std::string& name, const std::string& from, const std::string& to) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    spit(dir / name, t);
    return dir / name;
  };
  expect_node_error(variant("poly.vtu", "type=\"UnstructuredGrid\"", "type=\"PolyData\""),
                    {"poly.vtu: ", "type is PolyData, expected UnstructuredGrid"});
  expect_node_error(variant("big.vtu", "LittleEndian", "BigEndian"), {"byte_order is BigEndian"});
  expect_node_error(variant("h32.vtu", "header_type=\"UInt64\"", "header_type=\"UInt32\""), {"header_type is UInt32"});
  expect_node_error(variant("zlib.vtu", "header_type=\"UInt64\"", "header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\""),
                    {"compressed"});
  expect_node_error(variant("ascii.vtu", "format=\"appended\"", "format=\"ascii\""), {"format=\"ascii\""});
  expect_node_error(variant("notvtk.vtu", "<VTKFile", "<Other"), {"not a VTK XML file"});
  expect_node_error(variant("version.vtu", "pd_node_file_version", "pd_node_file_versiom"),
                    {"'pd_node_file_version' is missing"});
  fs::remove_all(dir);
}

TEST(NodeFile, RejectsBadValues) {
  const fs::path dir = temp_dir("values");
  pd::Nodes n = sample_nodes();
  n.volume[3] = 0.0;
  pd::write_node_file(dir / "vol.vtu", n);
  expect_node_error(dir / "vol.vtu", {"vol.vtu: node 3 has volume"});
  n = sample_nodes();
  n.block[2] = 0;
  pd::write_node_file(dir / "block.vtu", n);
  expect_node_error(dir / "block.vtu", {"node 2 has block 0"});
  n = sample_nodes();
  n.x[2][1] = 0.25;
  pd::write_node_file(dir / "z.vtu", n);
  expect_node_error(dir / "z.vtu", {"point 1 has z", "2D"});
  n = sample_nodes();
  n.sets[0].member[0] = 7;
  pd::write_node_file(dir / "set.vtu", n);
  expect_node_error(dir / "set.vtu", {"'set_left' has value 7 at node 0"});
  n = sample_nodes();
  n.sets[0].name = "9bad";
  pd::write_node_file(dir / "name.vtu", n);
  expect_node_error(dir / "name.vtu", {"unexpected PointData array 'set_9bad'"});
  expect_node_error(dir / "missing.vtu", {"missing.vtu: cannot open"});
  fs::remove_all(dir);
}

TEST(CaseFile, ReadsTheFormatsExample) {
  const pd::Case c = pd::parse_case(kCase, "out/x/case.json");
  EXPECT_EQ(c.nodes_file, fs::path("out/x/nodes.vtu"));
  EXPECT_EQ(c.analysis, "plane_stress");
  EXPECT_EQ(c.thickness, 0.001);
  ASSERT_EQ(c.blocks.size(), 1u);
  EXPECT_FALSE(c.blocks[0].parameter("fracture_energy").has_value());
  ASSERT_EQ(c.boundary_conditions.size(), 1u);
  EXPECT_EQ(c.boundary_conditions[0].component, 2);
  EXPECT_EQ(c.initial_conditions[0].value, 5.0);
  EXPECT_EQ(c.damping, 200.0);
  EXPECT_EQ(c.time.dt_rule, "stable");
  EXPECT_EQ(c.time.safety_factor, 0.8);
  ASSERT_TRUE(c.output.every_time.has_value());
  EXPECT_EQ(*c.output.every_time, 1e-4);
  EXPECT_FALSE(c.output.every_steps.has_value());
}

TEST(CaseFile, RejectsBadValuesNamingTheKey) {
  expect_case_error("\"safety_factor\": 0.8", "\"safety_factor\": -1", {"time.safety_factor: must be > 0"});
  expect_case_error("\"safety_factor\": 0.8", "\"safty_factor\": 0.8", {"time.safty_factor: unknown key (did you mean 'safety_factor'?)"});
  expect_case_error("\"dt\": \"stable\"", "\"dt\": \"exakt\"", {"time.dt: unknown rule 'exakt'; known: stable, exact"});
  expect_case_error("\"phi\": 1.0", "\"phi\": 0.2", {"adaptive.phi: must be between 0.5 and 1"});
  expect_case_error("\"kd\": 20", "\"kd\": 0", {"adaptive.kd: must be between 1 and 1000"});
  expect_case_error("\"tol\": 1e-3", "\"tol\": 1.5", {"adaptive.tol: must be below 1"});
  expect_case_error("\"dt_min\": null, \"dt_max\": null", "\"dt_min\": 1.0, \"dt_max\": 0.5", {"adaptive.dt_min: is larger than adaptive.dt_max"});
  expect_case_error("\"p\": 3.0", "\"p\": 3.0, \"pp\": 1", {"adaptive.pp: unknown key (did you mean 'p'?)"});
  expect_case_error("\"dt\": \"stable\"", "\"dt\": -1e-6", {"time.dt: must be > 0"});
  expect_case_error("\"integrator\": \"verlet\"", "\"integrator\": \"rk4\"", {"time.integrator: unknown integrator 'rk4'; known: adaptive, mixed, quasi_static, verlet"});
  expect_case_error("\"analysis\": \"plane_stress\"", "\"analysis\": \"planar\"", {"analysis: unknown analysis 'planar'; known: 3d, plane_strain, plane_stress"});
  expect_case_error("\"analysis\": \"plane_stress\"", "\"analysis\": \"3d\"", {"analysis: '3d' does not fit dimension 2"});
  expect_case_error("\"density\": 1200.0", "\"density\": \"heavy\"", {"blocks[0].density: must be a number"});
  expect_case_error("\"youngs_modulus\": 3.0e9", "\"youngs_modulus\": 0", {"blocks[0].youngs_modulus: must be > 0"});
  expect_case_error("\"fracture_energy\": null", "\"fracture_energy\": -2", {"blocks[0].fracture_energy: must be > 0"});
  expect_case_error("\"id\": 1", "\"id\": 2", {"blocks[0].id: must be 1"});
  expect_case_error("\"component\": 2, \"times\"", "\"component\": 3, \"times\"", {"boundary_conditions[0].component: must be between 0 and 2"});
  expect_case_error("\"times\": [0.0], \"values\": [0.0]", "\"times\": [0.0, 0.0], \"values\": [0.0, 1.0]",
                    {"boundary_conditions[0].times: must be strictly increasing"});
  expect_case_error("\"times\": [0.0], \"values\": [0.0]", "\"times\": [0.0], \"values\": [0.0, 1.0]",
                    {"boundary_conditions[0].values: has 2 entries but times has 1"});
  expect_case_error("\"kind\": \"velocity\"", "\"kind\": \"speed\"", {"initial_conditions[0].kind: unknown kind 'speed'"});
  expect_case_error("\"damping\": 200.0", "\"damping\": -1", {"damping: must be ≥ 0"});
  expect_case_error("\"every_steps\": null", "\"every_steps\": 10", {"output: exactly one of every_time and every_steps"});
  expect_case_error("\"history_every\": 1", "\"history_every\": 0", {"output.history_every: must be between 1"});
  expect_case_error("\"format_version\": 1", "\"format_version\": 2", {"format_version: is 2"});
  expect_case_error("\"thickness\": 0.001,", "", {"thickness: required key is missing"});
  expect_case_error("\"damping\": 200.0", "\"dampng\": 200.0", {"dampng: unknown key (did you mean 'damping'?)"});
  expect_case_error("\"horizon\": 0.0015075", "\"horizon\": 0.0015075,", {"not valid JSON"});
}
