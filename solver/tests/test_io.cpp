// File readers: the node file round-trips and bad node files / case files are rejected with
// messages that name the file and what (or which key) is wrong.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <regex>

#include "core/error.hpp"
#include "io/case_reader.hpp"
#include "io/node_file.hpp"
#include "io/output.hpp"
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
  expect_case_error("\"p\": 3.0, \"phi\"", "\"p\": 3.0, \"phi\": 1.0}, \"implicit\": {\"rho_infinity\": 1.5, \"p\"",
                    {"implicit.rho_infinity: must be between 0 and 1 (1: no numerical dissipation), got 1.5"});
  expect_case_error("\"p\": 3.0, \"phi\"", "\"p\": 3.0, \"phi\": 1.0}, \"implicit\": {\"newton_tol\": 2, \"p\"",
                    {"implicit.newton_tol: must be below 1 (a relative error), got 2"});
  expect_case_error("\"time\": {\"end\"", "\"mixed\": {\"start\": \"verlet\"}, \"time\": {\"end\"",
                    {"mixed.start: unknown value 'verlet'; known: quasi_static, implicit"});
  expect_case_error("\"p\": 3.0", "\"p\": 3.0, \"pp\": 1", {"adaptive.pp: unknown key (did you mean 'p'?)"});
  expect_case_error("\"dt\": \"stable\"", "\"dt\": -1e-6", {"time.dt: must be > 0"});
  expect_case_error("\"integrator\": \"verlet\"", "\"integrator\": \"rk4\"", {"time.integrator: unknown integrator 'rk4'; known: adaptive, implicit, mixed, quasi_static, verlet"});
  expect_case_error("\"analysis\": \"plane_stress\"", "\"analysis\": \"planar\"", {"analysis: unknown analysis 'planar'; known: 3d, plane_strain, plane_stress"});
  expect_case_error("\"analysis\": \"plane_stress\"", "\"analysis\": \"3d\"", {"analysis: '3d' does not fit dimension 2"});
  expect_case_error("\"density\": 1200.0", "\"density\": \"heavy\"", {"blocks[0].density: must be a number"});
  expect_case_error("\"youngs_modulus\": 3.0e9", "\"youngs_modulus\": 0", {"blocks[0].youngs_modulus: must be > 0"});
  expect_case_error("\"fracture_energy\": null", "\"fracture_energy\": -2", {"blocks[0].fracture_energy: must be > 0"});
  // A parameter of another model names it (PMB fixes ν; LPS has poisson_ratio), and LPS's ν range says why.
  expect_case_error("\"fracture_energy\": null", "\"fracture_energy\": null, \"poisson_ratio\": 0.3",
                    {"blocks[0].poisson_ratio: model 'pmb' has no parameter 'poisson_ratio'", "fixes Poisson's ratio",
                     "model 'lps' has it", "set model: lps"});
  expect_case_error("\"model\": \"pmb\"", "\"model\": \"lps\", \"poisson_ratio\": 0.5",
                    {"blocks[0].poisson_ratio: must be between -1.0 and 0.5 (exclusive), got 0.5: an isotropic solid needs"});
  expect_case_error("\"model\": \"pmb\"", "\"model\": \"lps\", \"poisson_ratio\": -1",
                    {"blocks[0].poisson_ratio: must be between -1.0 and 0.5 (exclusive), got -1"});
  expect_case_error("\"model\": \"pmb\"", "\"model\": \"lps\"", {"blocks[0].poisson_ratio: required key is missing"});
  expect_case_error("\"model\": \"pmb\"", "\"model\": \"lps\", \"poisson_ratio\": 0.3, \"influence\": \"cubic\"",
                    {"blocks[0].influence: unknown name 'cubic'; known: one, inverse_length, gaussian"});
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

// Frames in the compact encoding (output.precision float32, output.compression zlib): the bytes on
// disk are vtkZLibDataCompressor blocks (inflated here with zlib itself, not with our reader), and
// the values read back are the doubles rounded to float32.
TEST(Frames, Float32ZlibFrameReadsBackToFloat32RoundOff) {
  const fs::path dir = temp_dir("zlib_frame");
  const std::size_t n = 20000;  // 240 000 bytes of displacement: 8 blocks of 32 KiB, the last partial
  pd::VtuGrid g;
  std::vector<double> x(n), y(n), z(n, 0.0), u(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = 1e-3 * static_cast<double>(i % 200), y[i] = 1e-3 * static_cast<double>(i / 200),
                                      u[i] = 1e-5 * std::sin(0.001 * static_cast<double>(i)) + 1.0 / 3.0;
  g.field_data.push_back(pd::make_array("TIME", std::vector<double>{0.125}));
  g.points = pd::make_vec3_array("Points", x, y, z);
  g.point_data.push_back(pd::make_vec3_array<float>("displacement", u, x, y));
  g.point_data.push_back(pd::make_array_as<float>("damage", u));
  std::vector<std::int64_t> conn(n), offs(n);
  for (std::size_t i = 0; i < n; ++i) conn[i] = static_cast<std::int64_t>(i), offs[i] = static_cast<std::int64_t>(i + 1);
  g.connectivity = pd::make_array("connectivity", conn);
  g.offsets = pd::make_array("offsets", offs);
  g.types = pd::make_array("types", std::vector<std::uint8_t>(n, 1));
  pd::write_vtu(dir / "f.vtu", g, pd::VtuCompression::zlib);
  const std::string text = slurp(dir / "f.vtu");
  ASSERT_NE(text.find("compressor=\"vtkZLibDataCompressor\""), std::string::npos);

  // By hand: the displacement array's offset, its block header, and zlib's own inflate.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(text, m, std::regex("Name=\"displacement\" NumberOfComponents=\"3\" format=\"appended\" offset=\"([0-9]+)\"")));
  const std::size_t data = text.find('_', text.find("<AppendedData")) + 1;
  const auto* at = reinterpret_cast<const unsigned char*>(text.data()) + data + std::stoull(m[1]);
  std::uint64_t head[3];
  std::memcpy(head, at, sizeof head);
  const std::uint64_t bytes = 3 * n * sizeof(float);
  EXPECT_EQ(head[0], (bytes + 32767) / 32768);  // number of blocks
  EXPECT_EQ(head[1], 32768u);                   // block size
  EXPECT_EQ(head[2], bytes % 32768);            // the partial last block
  std::vector<unsigned char> inflated;
  std::size_t pos = 8 * (3 + head[0]);
  for (std::uint64_t k = 0; k < head[0]; ++k) {
    std::uint64_t csize = 0;
    std::memcpy(&csize, at + 8 * (3 + k), 8);
    std::vector<unsigned char> block(32768);
    uLongf got = block.size();
    ASSERT_EQ(uncompress(block.data(), &got, at + pos, csize), Z_OK) << "block " << k;
    inflated.insert(inflated.end(), block.begin(), block.begin() + static_cast<std::ptrdiff_t>(got));
    pos += csize;
  }
  ASSERT_EQ(inflated.size(), bytes);
  std::vector<float> by_hand(3 * n);
  std::memcpy(by_hand.data(), inflated.data(), bytes);
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(by_hand[3 * i], static_cast<float>(u[i])) << i;
    ASSERT_EQ(by_hand[3 * i + 1], static_cast<float>(x[i])) << i;
  }

  // And through our reader: Float32 fields to float32 round-off, Float64 points exact.
  const pd::VtuGrid r = pd::read_vtu(dir / "f.vtu");
  EXPECT_EQ(pd::values_of<double>(r.points), pd::values_of<double>(g.points));
  const auto damage = pd::values_as_double(*r.find(r.point_data, "damage"));
  ASSERT_EQ(damage.size(), n);
  for (std::size_t i = 0; i < n; ++i) EXPECT_NEAR(damage[i], u[i], 6e-8 * std::fabs(u[i])) << i;
  EXPECT_EQ(r.find(r.point_data, "displacement")->type, "Float32");
  EXPECT_LT(text.size(), 8u * n * 3 + 4u * n * 4);  // smaller than the raw points and fields alone

  // A damaged block is an error naming the file and saying the data are compressed.
  std::string cut = text;
  cut[data + std::stoull(m[1]) + 8 * (3 + head[0]) + 10] ^= 0x5a;
  spit(dir / "bad.vtu", cut);
  try {
    pd::read_vtu(dir / "bad.vtu");
    FAIL() << "a corrupted zlib block was accepted";
  } catch (const pd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.vtu"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("compressed"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(CaseFile, OutputFormatKeysAreCheckedAndDefaultToTheCompactFrames) {
  const std::string out = "\"history_every\": 1";
  expect_case_error(out, out + R"(, "fields": ["displacement", "velocty"])",
                    {"output.fields[1]: unknown field 'velocty' (did you mean 'velocity'?)",
                     "known: displacement, velocity, damage, block"});
  expect_case_error(out, out + R"(, "fields": ["damage", "damage"])", {"output.fields", "'damage' is listed twice"});
  expect_case_error(out, out + R"(, "precision": "float16")", {"output.precision: unknown value 'float16'; known: float32, float64"});
  expect_case_error(out, out + R"(, "compression": "lzma")", {"output.compression: unknown value 'lzma'; known: zlib, none"});
  expect_case_error(out, out + R"(, "gmsh": "some")", {"output.gmsh: unknown value 'some'; known: all, figures, none"});
  const pd::Case c = pd::parse_case(kCase, "out/x/case.json");
  EXPECT_EQ(c.output.precision, "float32");
  EXPECT_EQ(c.output.compression, "zlib");
  EXPECT_EQ(c.output.fields, (std::vector<std::string>{"displacement", "velocity", "damage", "block"}));
  std::string chosen = kCase;
  chosen.replace(chosen.find(out), out.size(), out + R"(, "fields": ["damage"], "precision": "float64", "compression": "none")");
  const pd::Case d = pd::parse_case(chosen, "out/x/case.json");
  EXPECT_EQ(d.output.fields, std::vector<std::string>{"damage"});
  const pd::FrameFormat f = pd::frame_format_of(d.output);
  EXPECT_FALSE(f.float32);
  EXPECT_FALSE(f.zlib);
}

// output_dir stays inside the run folder, the directory of case.json (issue 36, item 3): before,
// "/abs/path", "../../../x" and "sub/../../.." were taken, and frames, history.csv and run.log went
// there. Refused while reading case.json, before any file is written, naming the file and the key.
TEST(CaseFile, OutputDirMustStayInsideTheRunFolder) {
  const std::string dot = "\"output_dir\": \".\"";
  const std::string advice = "give a folder inside the directory of case.json, such as \".\" or \"out\"";
  expect_case_error(dot, "\"output_dir\": \"/abs/path\"",
                    {"output_dir: '/abs/path' is an absolute path; pdsolve writes only inside the run folder", advice});
  for (const std::string up : {"../../../x", "sub/../../..", "..", "./a/../../b"})
    expect_case_error(dot, "\"output_dir\": \"" + up + "\"",
                      {"output_dir: '" + up + "' leaves the run folder (the directory of case.json)", advice});
  // Inside, however written: the same folder the text names.
  for (const std::string inside : {".", "out", "a/../b", "./out/", "run/../run/frames"}) {
    std::string text = kCase;
    text.replace(text.find(dot), dot.size(), "\"output_dir\": \"" + inside + "\"");
    EXPECT_EQ(pd::parse_case(text, "out/x/case.json").output_dir, fs::path("out/x") / inside) << inside;
    // `pdsolve case.json` in the run folder itself (no directory in the path): refused before, the
    // folder not made yet compared as outside it.
    EXPECT_EQ(pd::parse_case(text, "case.json").output_dir, fs::path(inside)) << inside;
  }

  // A symbolic link in it is followed: out of the run folder it is refused, inside it is taken.
  const fs::path dir = temp_dir("output_dir_links");
  fs::create_directories(dir / "run" / "real");
  fs::create_directories(dir / "elsewhere");
  fs::create_directory_symlink(dir / "elsewhere", dir / "run" / "away");
  fs::create_directory_symlink("real", dir / "run" / "near");
  std::string away = kCase, near = kCase;
  away.replace(away.find(dot), dot.size(), "\"output_dir\": \"away/frames\"");
  near.replace(near.find(dot), dot.size(), "\"output_dir\": \"near\"");
  try {
    pd::parse_case(away, dir / "run" / "case.json");
    ADD_FAILURE() << "a link out of the run folder was taken";
  } catch (const pd::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find((dir / "run" / "case.json").string() + ": output_dir: 'away/frames' leads through a symbolic "
                        "link to " + (fs::canonical(dir / "elsewhere") / "frames").string() + ", outside the run folder " +
                        fs::canonical(dir / "run").string()), std::string::npos) << what;
  }
  EXPECT_EQ(pd::parse_case(near, dir / "run" / "case.json").output_dir, dir / "run" / "near");
  EXPECT_TRUE(fs::is_empty(dir / "elsewhere"));
  fs::remove_all(dir);
}

// output.restart_every_wall: 600 s of wall time when absent, 0 turns it off, below 0 is refused.
TEST(CaseFile, RestartEveryWallDefaultsTo600SecondsAndZeroIsOff) {
  EXPECT_EQ(pd::parse_case(kCase, "out/x/case.json").output.restart_every_wall, 600.0);
  const std::string out = "\"history_every\": 1";
  std::string off = kCase;
  off.replace(off.find(out), out.size(), out + R"(, "restart_every_wall": 0)");
  EXPECT_EQ(pd::parse_case(off, "out/x/case.json").output.restart_every_wall, 0.0);
  expect_case_error(out, out + R"(, "restart_every_wall": -1)", {"output.restart_every_wall: must be ≥ 0, got -1"});
  expect_case_error(out, out + R"(, "restart_every_wall": null)", {"output.restart_every_wall: must be a number, got null"});
}

// A fresh run rewrites frames.pvd (listing no frame) before it deletes the frames of the earlier
// run, so a run killed in between (kill -9) never leaves a .pvd listing deleted frames (issue 17,
// item 5). Before, the old .pvd stayed until the new run's first frame.
TEST(Frames, FreshRunEmptiesThePvdBeforeDeletingOldFrames) {
  const fs::path dir = temp_dir("fresh_pvd");
  fs::create_directories(dir / "frames");
  std::string old_pvd = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\">\n  <Collection>\n";
  for (int k = 0; k < 3; ++k) {
    const std::string name = "frames/frame_00000" + std::to_string(k) + ".vtu";
    spit(dir / name, "old frame");
    old_pvd += "    <DataSet timestep=\"" + std::to_string(k) + "\" file=\"" + name + "\"/>\n";
  }
  spit(dir / "frames.pvd", old_pvd + "  </Collection>\n</VTKFile>\n");
  {
    const pd::OutputWriter out(dir);
    EXPECT_FALSE(fs::exists(dir / "frames" / "frame_000000.vtu"));
    const std::string pvd = slurp(dir / "frames.pvd");
    EXPECT_EQ(pvd.find("DataSet"), std::string::npos) << pvd;
    EXPECT_NE(pvd.find("<Collection>"), std::string::npos) << pvd;
  }
  fs::remove_all(dir);
}

// Not a file, or a coordinate no distance can be computed from (issue 17, item 9): a clear error
// naming the file, not "basic_filebuf::underflow", an endless read of /dev/zero or "max_size()".
TEST(NodeFile, DirectoryDeviceAndFarCoordinatesAreRefused) {
  const fs::path dir = temp_dir("not_a_file");
  expect_node_error(dir, {dir.string() + ": a directory, not the VTK file; give the path of the file"});
  expect_node_error("/dev/zero", {"/dev/zero: not a regular file, not the VTK file"});
  pd::Nodes n = sample_nodes();
  n.x[0][4] = 1e300;
  pd::write_node_file(dir / "far.vtu", n);
  expect_node_error(dir / "far.vtu", {"far.vtu: point 4 has coordinate x = 1e+300 m, beyond ±1e+150 m"});
  EXPECT_THROW(pd::read_case(dir), pd::Error);
  try {
    pd::read_case(dir);
  } catch (const pd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("a directory, not the case file"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}
