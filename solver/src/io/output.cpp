// Writers of frames, the .pvd collection and history.csv (run.log: run/run_log.hpp).
#include "io/output.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/vtu.hpp"

namespace pd {

const char* const kHistoryHeader =
    "step,time,dt,iterations,rejected,kinetic_energy,strain_energy,external_work,damping_work,broken_bonds,wall_time";

const std::vector<std::string>& frame_fields() {
  static const std::vector<std::string> names = {"displacement", "velocity", "damage", "block"};
  return names;
}

FrameFormat frame_format_of(const OutputSettings& output) {
  return FrameFormat{output.precision == "float32", output.compression == "zlib", output.fields};
}

void write_frame(const std::filesystem::path& path, const Model& model, const State& state, double time,
                 std::int64_t step, const FrameFormat& format, const FrameBonds* bonds) {
  write_vtu(path, frame_grid(model, state, time, step, format, nullptr, bonds),
            format.zlib ? VtuCompression::zlib : VtuCompression::none);
}

VtuGrid frame_grid(const Model& model, const State& state, double time, std::int64_t step, const FrameFormat& format,
                   const FramePiece* piece, const FrameBonds* bonds) {
  const std::size_t n = model.nodes.size();
  VtuGrid g;
  // TIME and step stay exact: readers match frames to history.csv rows and the .pvd by them.
  g.field_data.push_back(make_array("TIME", std::vector<double>{time}));
  g.field_data.push_back(make_array("step", std::vector<std::int64_t>{step}));
  // The reference points stay Float64 whatever the precision: post-processing differences them
  // (strains from u over neighbouring nodes; the nearest node to a probe), a float32 coordinate
  // would be off by up to 3e-9 m at 0.05 m, and compressed they cost little because every frame
  // repeats the same lattice (cases/plate_with_hole/README.md, "Output size").
  g.points = make_vec3_array("Points", model.nodes.x[0], model.nodes.x[1], model.nodes.x[2]);
  auto wanted = [&](const char* name) {
    return std::find(format.fields.begin(), format.fields.end(), name) != format.fields.end();
  };
  auto vec3 = [&](const char* name, const Vec3Array& c) {
    return format.float32 ? make_vec3_array<float>(name, c[0], c[1], c[2]) : make_vec3_array<double>(name, c[0], c[1], c[2]);
  };
  // In the order of frame_fields(), whatever the order of output.fields.
  if (wanted("displacement")) g.point_data.push_back(vec3("displacement", state.u));
  if (wanted("velocity")) g.point_data.push_back(vec3("velocity", state.v));
  if (wanted("damage")) {
    const std::vector<double> damage = bonds ? bonds->damage : model.bond_model->damage(model);
    g.point_data.push_back(format.float32 ? make_array_as<float>("damage", damage) : make_array("damage", damage));
  }
  if (wanted("block")) g.point_data.push_back(make_array("block", model.nodes.block));  // an integer: as is
  // The law's declared per-node history with `frames` (core/state_arrays.hpp), under its declared
  // name, after the fields output.fields chooses, at the frames' precision.
  for (const StateArray& a : model.state_arrays.all()) {
    const StateDeclaration& d = a.declaration;
    if (!d.frames || d.extent != StateExtent::per_node) continue;
    if (d.components == 1) g.point_data.push_back(format.float32 ? make_array_as<float>(d.name, a.values) : make_array(d.name, a.values));
    else g.point_data.push_back(format.float32 ? make_array(d.name, std::vector<float>(a.values.begin(), a.values.end()), d.components)
                                               : make_array(d.name, a.values, d.components));
  }

  // Cells: a vertex per node, then a line per broken bond (each once, from its end i < j), in node
  // order. Counted per node in parallel, so a frame does not walk every bond on one thread.
  const auto& b = bonds ? bonds->broken_lines : model.bonds;
  std::vector<std::int64_t> first_line(n + 1, 0);  // broken bonds i < j before node i
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
    std::int64_t count = 0;
    for (std::int64_t k = b.offsets[static_cast<std::size_t>(i)]; k < b.offsets[static_cast<std::size_t>(i) + 1]; ++k)
      count += b.broken[static_cast<std::size_t>(k)] && b.neighbour[static_cast<std::size_t>(k)] > i;
    first_line[static_cast<std::size_t>(i) + 1] = count;
  }
  for (std::size_t i = 0; i < n; ++i) first_line[i + 1] += first_line[i];
  const auto lines = static_cast<std::size_t>(first_line[n]);
  std::vector<std::int64_t> conn(n + 2 * lines), offs(n + lines);
  std::vector<std::uint8_t> types(n + lines, 3), broken_flag(n + lines, 1);  // VTK_LINE, broken
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
    const auto q = static_cast<std::size_t>(i);
    conn[q] = i;  // the vertex cell of node i
    offs[q] = i + 1;
    types[q] = 1;  // VTK_VERTEX
    broken_flag[q] = 0;
    std::size_t cell = n + static_cast<std::size_t>(first_line[q]);
    for (std::int64_t k = b.offsets[q]; k < b.offsets[q + 1]; ++k) {
      const std::int64_t j = b.neighbour[static_cast<std::size_t>(k)];
      if (!b.broken[static_cast<std::size_t>(k)] || j < i) continue;
      const std::size_t at = n + 2 * (cell - n);
      conn[at] = i;
      conn[at + 1] = j;
      offs[cell] = static_cast<std::int64_t>(at + 2);
      ++cell;
    }
  }
  g.connectivity = make_array("connectivity", conn);
  g.offsets = make_array("offsets", offs);
  g.types = make_array("types", types);
  g.cell_data.push_back(make_array("broken_bond", broken_flag));
  if (piece) {
    // A ghost's point and vertex cell are its owner's (VTK's DUPLICATEPOINT, DUPLICATECELL = 1);
    // line cells come from owned rows only (a ghost's row is empty), so each bond is in one piece.
    std::vector<std::uint8_t> ghost_point(n), ghost_cell(n + lines, 0);
    for (std::size_t l = 0; l < n; ++l) ghost_point[l] = ghost_cell[l] = piece->owned[l] ? 0 : 1;
    g.point_data.push_back(make_array("node_id", piece->global));
    g.point_data.push_back(make_array("vtkGhostType", ghost_point));
    g.cell_data.push_back(make_array("vtkGhostType", ghost_cell));
  }
  return g;
}

std::string frame_piece_file(std::size_t k, int rank) {
  char name[80];
  std::snprintf(name, sizeof name, "frames/frame_%06zu_p%d.vtu", k, rank);
  return name;
}

namespace {

double clock_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

std::string OutputWriter::frame_file(std::size_t k) const {
  char name[64];
  std::snprintf(name, sizeof name, "frames/frame_%06zu.%s", k, format_.pieces ? "pvtu" : "vtu");
  return name;
}

OutputWriter::OutputWriter(std::filesystem::path output_dir, const std::vector<std::string>& extra_columns,
                           const OutputResume* resume, FrameFormat format)
    : dir_(std::move(output_dir)), format_(std::move(format)) {
  std::error_code ec;
  std::filesystem::create_directories(dir_ / "frames", ec);
  if (ec) throw Error((dir_ / "frames").string() + ": cannot create the directory: " + ec.message());
  std::string header = kHistoryHeader;
  for (const auto& name : extra_columns) header += ',' + name;
  header += '\n';
  const std::filesystem::path history = dir_ / "history.csv";
  if (resume) {
    // Every check first, so a refused restart changes no file.
    history_fd_ = ::open(history.c_str(), O_RDWR | O_CLOEXEC);
    if (history_fd_ < 0) throw Error(history.string() + ": cannot open for the restart: " + std::strerror(errno));
    const off_t size = ::lseek(history_fd_, 0, SEEK_END);
    std::string head(header.size(), '\0');
    const bool short_file = size < 0 || static_cast<std::uint64_t>(size) < resume->history_bytes;
    const bool same_header =
        ::pread(history_fd_, head.data(), head.size(), 0) == static_cast<ssize_t>(head.size()) && head == header;
    if (short_file || !same_header) {
      ::close(history_fd_);
      history_fd_ = -1;
      finished_ = true;
      if (short_file)
        throw Error(history.string() + ": " + std::to_string(size) + " bytes, shorter than the " +
                    std::to_string(resume->history_bytes) + " the checkpoint wrote; cannot restart");
      throw Error(history.string() + ": its header is not the one this case writes; cannot restart");
    }
    for (std::size_t k = 0; k < resume->frame_times.size(); ++k) {
      if (!std::filesystem::is_regular_file(dir_ / frame_file(k))) {
        ::close(history_fd_);
        history_fd_ = -1;
        finished_ = true;
        throw Error((dir_ / frame_file(k)).string() + ": missing, but the checkpoint counts " +
                    std::to_string(resume->frame_times.size()) + " frames written; cannot restart");
      }
      frames_.emplace_back(resume->frame_times[k], frame_file(k));
    }
  }
  // frames.pvd first, listing only the frames kept (none in a fresh run), then the other frames go:
  // a run killed between the two (kill -9) leaves a .pvd that lists no deleted frame (issue 17,
  // item 5). Before, a fresh run rewrote it only with its first frame.
  write_pvd();
  // Frames of an earlier, longer run (or written after the checkpoint) would otherwise sit next to
  // the new ones.
  // A run in pieces (output.parallel_frames) names frame_NNNNNN.pvtu and frame_NNNNNN_pR.vtu.
  static const std::regex frame_name("frame_([0-9]{6})(_p[0-9]+\\.vtu|\\.vtu|\\.pvtu)(\\.part)?");
  std::smatch match;
  for (const auto& entry : std::filesystem::directory_iterator(dir_ / "frames")) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && std::regex_match(name, match, frame_name) &&
        (match[3].matched || std::stoul(match[1].str()) >= frames_.size()))
      std::filesystem::remove(entry.path());
  }
  if (resume) {
    // Rows after the checkpoint (from a run killed later) are cut off: the restart writes them again.
    if (::ftruncate(history_fd_, static_cast<off_t>(resume->history_bytes)) != 0 ||
        ::lseek(history_fd_, 0, SEEK_END) < 0)
      throw Error(history.string() + ": cannot cut back to the checkpoint: " + std::strerror(errno));
    history_bytes_ = resume->history_bytes;
  } else {
    history_fd_ = ::open(history.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (history_fd_ < 0) throw Error(history.string() + ": cannot open for writing: " + std::strerror(errno));
    history_buffer_ = header;
    flush_history();
  }
  last_flush_ = clock_seconds();
}

OutputWriter::~OutputWriter() {
  try {
    finish();
  } catch (...) {
  }
}

void OutputWriter::write_pvd() const {
  std::ostringstream pvd;
  pvd.precision(17);
  pvd << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      << "  <Collection>\n";
  for (const auto& [t, file] : frames_)
    pvd << "    <DataSet timestep=\"" << t << "\" group=\"\" part=\"0\" file=\"" << file << "\"/>\n";
  pvd << "  </Collection>\n</VTKFile>\n";
  write_file_atomically(dir_ / "frames.pvd", pvd.str());
}

void OutputWriter::frame(const Model& model, const State& state, double time, std::int64_t step, const FrameBonds* bonds) {
  const std::string name = frame_file(frames_.size());
  write_frame(dir_ / name, model, state, time, step, format_, bonds);
  frames_.emplace_back(time, name);
  write_pvd();
  flush_history();
}

void OutputWriter::frame_of_pieces(const VtuGrid& rank0_grid, int ranks, double time) {
  const std::size_t k = frames_.size();
  // VTK's PUnstructuredGrid: the arrays every piece holds (name, type, components), then the pieces,
  // relative to the .pvtu's directory (frames/).
  std::ostringstream text;
  const auto declare = [&text](const char* section, const std::vector<VtuArray>& arrays) {
    text << "    <" << section << ">\n";
    for (const VtuArray& a : arrays)
      text << "      <PDataArray type=\"" << a.type << "\" Name=\"" << a.name << "\" NumberOfComponents=\""
           << a.components << "\"/>\n";
    text << "    </" << section << ">\n";
  };
  text << "<?xml version=\"1.0\"?>\n"
       << "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
       << "  <PUnstructuredGrid GhostLevel=\"0\">\n";
  declare("PPointData", rank0_grid.point_data);
  declare("PCellData", rank0_grid.cell_data);
  text << "    <PPoints>\n      <PDataArray type=\"" << rank0_grid.points.type << "\" NumberOfComponents=\"3\"/>\n"
       << "    </PPoints>\n";
  for (int r = 0; r < ranks; ++r)
    text << "    <Piece Source=\"" << std::filesystem::path(frame_piece_file(k, r)).filename().string() << "\"/>\n";
  text << "  </PUnstructuredGrid>\n</VTKFile>\n";
  write_file_atomically(dir_ / frame_file(k), text.str());
  frames_.emplace_back(time, frame_file(k));
  write_pvd();
  flush_history();
}

int OutputWriter::drop_frames_after(double time) {
  std::vector<std::string> dropped;
  while (!frames_.empty() && frames_.back().first > time) {
    dropped.push_back(frames_.back().second);
    frames_.pop_back();
  }
  if (dropped.empty()) return 0;
  write_pvd();  // first: the .pvd never lists a removed frame
  for (const auto& file : dropped) {
    std::error_code ignored;
    std::filesystem::remove(dir_ / file, ignored);
  }
  if (format_.pieces)  // and their pieces, written by every rank
    for (const auto& entry : std::filesystem::directory_iterator(dir_ / "frames")) {
      const std::string name = entry.path().filename().string();
      static const std::regex piece_name("frame_([0-9]{6})_p[0-9]+\\.vtu");
      std::smatch match;
      std::error_code ignored;
      if (std::regex_match(name, match, piece_name) && std::stoul(match[1].str()) >= frames_.size())
        std::filesystem::remove(entry.path(), ignored);
    }
  return static_cast<int>(dropped.size());
}

std::vector<double> OutputWriter::frame_times() const {
  std::vector<double> times;
  for (const auto& frame : frames_) times.push_back(frame.first);
  return times;
}

namespace {

// ",value" by std::to_chars: for a double, the shortest form that reads back as the same double,
// every digit a reader needs and none it does not, several times faster than printf's %.17g (run
// per step when history_every is 1).
template <class T>
void append_chars(std::string& out, T value) {
  char text[32];
  text[0] = ',';
  const auto end = std::to_chars(text + 1, text + sizeof text, value).ptr;
  out.append(text, end);
}

void append_value(std::string& out, long long value) { append_chars(out, value); }

void append_value(std::string& out, double value) {
  // A whole number (a count such as contact_rebuilds) as an integer: the shortest form of 100000.0
  // is "1e+05". Exact below 2⁵³, where every integer is a double.
  if (std::fabs(value) < 9007199254740992.0 && value == std::trunc(value) && !(value == 0.0 && std::signbit(value)))
    append_chars(out, static_cast<long long>(value));
  else
    append_chars(out, value);
}

}  // namespace

void OutputWriter::history(const HistoryRow& r) {
  const std::size_t start = history_buffer_.size();
  append_value(history_buffer_, static_cast<long long>(r.step));
  history_buffer_.erase(start, 1);  // no comma before the first column
  append_value(history_buffer_, r.time);
  append_value(history_buffer_, r.dt);
  append_value(history_buffer_, static_cast<long long>(r.iterations));
  append_value(history_buffer_, static_cast<long long>(r.rejected));
  append_value(history_buffer_, r.kinetic_energy);
  append_value(history_buffer_, r.strain_energy);
  append_value(history_buffer_, r.external_work);
  append_value(history_buffer_, r.damping_work);
  append_value(history_buffer_, static_cast<long long>(r.broken_bonds));
  char wall[32];
  std::snprintf(wall, sizeof wall, ",%.6f", r.wall_time);  // microseconds are all a clock reading has
  history_buffer_ += wall;
  for (double value : r.extra) append_value(history_buffer_, value);
  history_buffer_ += '\n';
  if (history_buffer_.size() >= (64u << 10) || clock_seconds() - last_flush_ > 1.0) flush_history();
}

void OutputWriter::flush_history() {
  const std::string file = (dir_ / "history.csv").string();
  if (history_fd_ < 0) {
    if (!history_buffer_.empty()) throw Error(file + ": written after it was closed");
    return;
  }
  std::size_t done = 0;
  while (done < history_buffer_.size()) {
    const ssize_t w = ::write(history_fd_, history_buffer_.data() + done, history_buffer_.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      // A write cut short (a full disk) is cut back to the rows on disk before it, so history.csv
      // always ends with a whole row; the rows not written are dropped, not retried at exit.
      const int error_number = w == 0 ? ENOSPC : errno;
      const std::size_t lost = history_buffer_.size();
      history_buffer_.clear();
      if (::ftruncate(history_fd_, static_cast<off_t>(history_bytes_)) != 0 ||
          ::lseek(history_fd_, 0, SEEK_END) < 0) {
        ::close(history_fd_);
        history_fd_ = -1;
        throw Error(file + ": write failed and cannot cut back to whole rows: " + std::strerror(errno));
      }
      throw_write_error(file, "write failed", error_number, lost);
    }
    done += static_cast<std::size_t>(w);
  }
  history_bytes_ += history_buffer_.size();
  history_buffer_.clear();
  last_flush_ = clock_seconds();
}

void OutputWriter::finish() {
  if (finished_) return;
  finished_ = true;
  flush_history();
  const int fd = history_fd_;
  history_fd_ = -1;
  if (fd >= 0 && ::close(fd) != 0) throw_write_error(dir_ / "history.csv", "write failed", errno, 0);
}

}  // namespace pd
