// Writers of frames, the .pvd collection, history.csv and run.log.
#include "io/output.hpp"

#include <cstdio>
#include <iostream>
#include <regex>
#include <sstream>

#include "core/error.hpp"
#include "forces/pmb.hpp"
#include "io/vtu.hpp"

namespace pd {

const char* const kHistoryHeader =
    "step,time,dt,iterations,rejected,kinetic_energy,strain_energy,external_work,damping_work,broken_bonds,wall_time";

void write_frame(const std::filesystem::path& path, const Model& model, const State& state, double time,
                 std::int64_t step) {
  const std::size_t n = model.nodes.size();
  VtuGrid g;
  g.field_data.push_back(make_array("TIME", std::vector<double>{time}));
  g.field_data.push_back(make_array("step", std::vector<std::int64_t>{step}));
  g.points = make_vec3_array("Points", model.nodes.x[0], model.nodes.x[1], model.nodes.x[2]);
  g.point_data.push_back(make_vec3_array("displacement", state.u[0], state.u[1], state.u[2]));
  g.point_data.push_back(make_vec3_array("velocity", state.v[0], state.v[1], state.v[2]));
  g.point_data.push_back(make_array("damage", damage(model)));
  g.point_data.push_back(make_array("block", model.nodes.block));

  std::vector<std::int64_t> conn, offs;
  std::vector<std::uint8_t> types(n, 1), broken_flag(n, 0);
  conn.reserve(n);
  offs.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    conn.push_back(static_cast<std::int64_t>(i));
    offs.push_back(static_cast<std::int64_t>(i) + 1);
  }
  const auto& b = model.bonds;
  for (std::size_t i = 0; i < n; ++i)
    for (auto k = static_cast<std::size_t>(b.offsets[i]); k < static_cast<std::size_t>(b.offsets[i + 1]); ++k) {
      const auto j = static_cast<std::size_t>(b.neighbour[k]);
      if (!b.broken[k] || j < i) continue;  // each broken bond once, i < j
      conn.push_back(static_cast<std::int64_t>(i));
      conn.push_back(static_cast<std::int64_t>(j));
      offs.push_back(static_cast<std::int64_t>(conn.size()));
      types.push_back(3);  // VTK_LINE
      broken_flag.push_back(1);
    }
  g.connectivity = make_array("connectivity", conn);
  g.offsets = make_array("offsets", offs);
  g.types = make_array("types", types);
  g.cell_data.push_back(make_array("broken_bond", broken_flag));
  write_vtu(path, g);
}

OutputWriter::OutputWriter(std::filesystem::path output_dir, const std::vector<std::string>& extra_columns)
    : dir_(std::move(output_dir)) {
  std::error_code ec;
  std::filesystem::create_directories(dir_ / "frames", ec);
  if (ec) throw Error((dir_ / "frames").string() + ": cannot create the directory: " + ec.message());
  // Frames of an earlier, longer run would otherwise sit next to the new ones.
  static const std::regex frame_name("frame_[0-9]{6}\\.vtu(\\.part)?");
  for (const auto& entry : std::filesystem::directory_iterator(dir_ / "frames"))
    if (entry.is_regular_file() && std::regex_match(entry.path().filename().string(), frame_name))
      std::filesystem::remove(entry.path());
  history_.open(dir_ / "history.csv.part", std::ios::trunc);
  if (!history_) throw Error((dir_ / "history.csv.part").string() + ": cannot open for writing");
  history_ << kHistoryHeader;
  for (const auto& name : extra_columns) history_ << ',' << name;
  history_ << '\n';
}

OutputWriter::~OutputWriter() {
  try {
    finish();
  } catch (...) {
  }
}

void OutputWriter::frame(const Model& model, const State& state, double time, std::int64_t step) {
  char name[64];
  std::snprintf(name, sizeof name, "frames/frame_%06d.vtu", frames_written());
  write_frame(dir_ / name, model, state, time, step);
  frames_.emplace_back(time, name);
  std::ostringstream pvd;
  pvd.precision(17);
  pvd << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      << "  <Collection>\n";
  for (const auto& [t, file] : frames_)
    pvd << "    <DataSet timestep=\"" << t << "\" group=\"\" part=\"0\" file=\"" << file << "\"/>\n";
  pvd << "  </Collection>\n</VTKFile>\n";
  write_file_atomically(dir_ / "frames.pvd", pvd.str());
  history_.flush();
}

void OutputWriter::history(const HistoryRow& r) {
  char line[512];
  std::snprintf(line, sizeof line, "%lld,%.17g,%.17g,%d,%d,%.17g,%.17g,%.17g,%.17g,%lld,%.6f\n",
                static_cast<long long>(r.step), r.time, r.dt, r.iterations, r.rejected, r.kinetic_energy,
                r.strain_energy, r.external_work, r.damping_work, static_cast<long long>(r.broken_bonds),
                r.wall_time);
  std::string text = line;
  if (!r.extra.empty()) {
    text.pop_back();  // the newline
    for (double value : r.extra) {
      std::snprintf(line, sizeof line, ",%.17g", value);
      text += line;
    }
    text += '\n';
  }
  history_ << text;
}

void OutputWriter::finish() {
  if (finished_) return;
  finished_ = true;
  history_.close();
  if (!history_) throw Error((dir_ / "history.csv.part").string() + ": write failed (disk full?)");
  std::error_code ec;
  std::filesystem::rename(dir_ / "history.csv.part", dir_ / "history.csv", ec);
  if (ec) throw Error((dir_ / "history.csv").string() + ": cannot rename into place: " + ec.message());
}

void RunLog::line(const std::string& text) {
  if (!quiet_) std::cout << text << std::endl;
  text_ += text + "\n";
  write_file_atomically(path_, text_);
}

void RunLog::error(const std::string& text) {
  std::cerr << text << std::endl;
  text_ += text + "\n";
  write_file_atomically(path_, text_);
}

}  // namespace pd
