// Writer and reader of checkpoint.bin (io/checkpoint.hpp, pipeline/formats.md §5).
#include "io/checkpoint.hpp"

#include "io/read_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <string_view>
#include <iterator>
#include <regex>
#include <type_traits>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/vtu.hpp"

namespace pd {

namespace {

constexpr char kMagic[8] = {'P', 'D', 'C', 'K', 'P', 'T', '\r', '\n'};
constexpr std::uint32_t kByteOrderMark = 0x01020304;
constexpr const char* kPiecesFolder = "checkpoint.pieces";

// `h`: the hash of the bytes before these (FNV-1a runs over its input in order).
std::uint64_t fnv1a(const char* data, std::size_t size, std::uint64_t h = 14695981039346656037ull) {
  for (std::size_t k = 0; k < size; ++k) {
    h ^= static_cast<unsigned char>(data[k]);
    h *= 1099511628211ull;
  }
  return h;
}

class Writer {
 public:
  template <class T>
  void scalar(const T& value) {
    static_assert(std::is_arithmetic_v<T>);
    const auto* p = reinterpret_cast<const char*>(&value);
    bytes_.append(p, sizeof value);
  }
  template <class T>
  void array(const std::vector<T>& values) {
    static_assert(std::is_arithmetic_v<T>);
    scalar(static_cast<std::uint64_t>(values.size()));
    if (!values.empty()) bytes_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  }
  void vec3(const Vec3Array& a) {
    for (const auto& c : a) array(c);
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

class Reader {
 public:
  Reader(const std::string& bytes, std::size_t begin, std::size_t end, std::string file)
      : bytes_(bytes), at_(begin), end_(end), file_(std::move(file)) {}
  template <class T>
  void scalar(T& value) {
    static_assert(std::is_arithmetic_v<T>);
    need(sizeof value);
    std::memcpy(&value, bytes_.data() + at_, sizeof value);
    at_ += sizeof value;
  }
  template <class T>
  void array(std::vector<T>& values) {
    std::uint64_t count = 0;
    scalar(count);
    if (count > (end_ - at_) / sizeof(T)) fail("an array runs past the end of the payload");
    values.resize(static_cast<std::size_t>(count));
    if (!values.empty()) std::memcpy(values.data(), bytes_.data() + at_, values.size() * sizeof(T));
    at_ += values.size() * sizeof(T);
  }
  void vec3(Vec3Array& a) {
    for (auto& c : a) array(c);
  }
  void done() const {
    if (at_ != end_) fail("the payload has " + std::to_string(end_ - at_) + " bytes more than expected");
  }
  [[noreturn]] void fail(const std::string& what) const { throw Error(file_ + ": not a valid checkpoint: " + what); }

 private:
  void need(std::size_t size) const {
    if (end_ - at_ < size) fail("the payload ends early");
  }
  const std::string& bytes_;
  std::size_t at_, end_;
  std::string file_;
};

// One field list for both directions, so writer and reader cannot drift apart.
// A text field: an array of chars.
template <class IO>
void text(IO& io, std::string& s) {
  std::vector<char> chars(s.begin(), s.end());
  io.array(chars);
  s.assign(chars.begin(), chars.end());
}

// The index's list of the pieces' arrays.
template <class IO>
void sections(IO& io, std::vector<CheckpointSection>& list) {
  auto count = static_cast<std::uint64_t>(list.size());
  io.scalar(count);
  if constexpr (std::is_same_v<IO, Reader>) {
    if (count > 4096) io.fail("more arrays than any model holds (" + std::to_string(count) + ")");
    list.resize(static_cast<std::size_t>(count));
  }
  for (CheckpointSection& a : list) {
    text(io, a.name);
    auto per_bond = static_cast<std::uint8_t>(a.per_bond), bytes = static_cast<std::uint8_t>(a.bytes);
    auto width = static_cast<std::int32_t>(a.width);
    io.scalar(per_bond), io.scalar(bytes), io.scalar(width);
    if constexpr (std::is_same_v<IO, Reader>) {
      if (per_bond > 1 || bytes > 1 || width < 1 || width > 1024 || a.name.empty())
        io.fail("array '" + a.name + "' is declared with no valid extent, kind or width");
      a.per_bond = per_bond != 0, a.bytes = bytes != 0, a.width = width;
    }
  }
}

template <class IO>
void pieces(IO& io, std::vector<CheckpointPieceRef>& list) {
  auto count = static_cast<std::uint64_t>(list.size());
  io.scalar(count);
  if constexpr (std::is_same_v<IO, Reader>) {
    if (count == 0 || count > (1u << 20)) io.fail("it names " + std::to_string(count) + " pieces");
    list.resize(static_cast<std::size_t>(count));
  }
  for (CheckpointPieceRef& p : list) {
    text(io, p.file);
    io.scalar(p.nodes), io.scalar(p.bonds), io.scalar(p.bytes), io.scalar(p.checksum);
    if constexpr (std::is_same_v<IO, Reader>) {
      // A piece sits in checkpoint.pieces/ beside the index, nowhere else.
      const std::string folder = std::string(kPiecesFolder) + "/";
      if (p.file.rfind(folder, 0) != 0 || p.file.find('/', folder.size()) != std::string::npos ||
          p.file.find("..") != std::string::npos || p.file.size() == folder.size())
        io.fail("a piece named '" + p.file + "', not a file in " + kPiecesFolder + "/");
    }
  }
}

template <class IO>
void fields(IO& io, Checkpoint& c) {
  io.scalar(c.case_hash), io.scalar(c.nodes_hash), io.scalar(c.nodes), io.scalar(c.directed_bonds);
  text(io, c.integrator);
  LoopState& l = c.loop;
  io.scalar(l.step), io.scalar(l.t), io.scalar(l.dt), io.scalar(l.dt_taken);
  io.scalar(l.last_frame_step), io.scalar(l.next_frame_index), io.scalar(l.next_restart_index);
  io.scalar(l.broken), io.scalar(l.force_evaluations), io.scalar(l.broken_energy), io.scalar(l.wall_time);
  io.scalar(l.growth.energy_before), io.scalar(l.growth.streak_start), io.scalar(l.growth.streak);
  io.array(c.integrator_state);
  State& s = c.state;
  io.array(s.term_energies);  // version 5: one list (version 4: contact's, then indenters' at the end)
  std::vector<double> indenter;
  for (const auto& force : s.indenter_force) indenter.insert(indenter.end(), force.begin(), force.end());
  io.array(indenter);
  // Three components per indenter: a remainder would be dropped without a word.
  if constexpr (std::is_same_v<IO, Reader>)
    if (indenter.size() % 3 != 0) io.fail("indenter forces are not whole (x, y, z) triples");
  s.indenter_force.resize(indenter.size() / 3);
  for (std::size_t k = 0; k < s.indenter_force.size(); ++k)
    for (std::size_t d = 0; d < 3; ++d) s.indenter_force[k][d] = indenter[3 * k + d];
  io.scalar(s.external_power), io.scalar(s.damping_power), io.scalar(s.external_work), io.scalar(s.damping_work);
  sections(io, c.sections);  // version 6: the arrays are in the pieces
  io.scalar(c.contact_rebuilds), io.scalar(c.contact_seconds);
  io.array(c.frame_times), io.scalar(c.history_bytes);
  text(io, c.linear_solver);  // version 4 (issue 36)
  auto in_pieces = static_cast<std::uint8_t>(c.frames_in_pieces);
  io.scalar(in_pieces);  // version 6
  c.frames_in_pieces = in_pieces != 0;
  pieces(io, c.pieces);  // version 6
}

// Header + payload + checksum, as both files are framed.
std::string framed(const std::string& payload) {
  Writer head;
  head.scalar(kCheckpointVersion);
  head.scalar(kByteOrderMark);
  head.scalar(static_cast<std::uint64_t>(payload.size()));
  Writer sum;
  sum.scalar(fnv1a(payload.data(), payload.size()));
  return std::string(kMagic, sizeof kMagic) + head.bytes() + payload + sum.bytes();
}

constexpr std::size_t kHead = sizeof kMagic + 4 + 4 + 8;
constexpr std::uint32_t kPieceTag = 0x43454950;  // "PIEC"

// A piece's bytes read in order, the checksum summed as they pass, never the whole file at once.
class PieceStream {
 public:
  PieceStream(const std::filesystem::path& path, std::string name) : in_(path, std::ios::binary), name_(std::move(name)) {}
  bool open() const { return static_cast<bool>(in_); }
  void read(void* into, std::size_t size) {
    if (size > left_) fail("its payload ends early");
    in_.read(static_cast<char*>(into), static_cast<std::streamsize>(size));
    if (!in_) fail("cannot be read to its end (truncated?)");
    const auto* p = static_cast<const unsigned char*>(into);
    for (std::size_t k = 0; k < size; ++k) {
      sum_ ^= p[k];
      sum_ *= 1099511628211ull;
    }
    left_ -= size;
  }
  template <class T>
  T scalar() {
    T value{};
    read(&value, sizeof value);
    return value;
  }
  void raw(void* into, std::size_t size) {  // the header, outside the checksum
    in_.read(static_cast<char*>(into), static_cast<std::streamsize>(size));
    if (!in_) fail("shorter than its header");
  }
  std::uint64_t left_ = 0;
  std::uint64_t sum() const { return sum_; }
  [[noreturn]] void fail(const std::string& what) const { throw Error(name_ + ": not a valid checkpoint piece: " + what); }

 private:
  std::ifstream in_;
  std::string name_;
  std::uint64_t sum_ = 14695981039346656037ull;
};

// The entries [at, at + count) of a streamed array (`width` elements of `size` bytes each) that
// the runs keep, copied into dst; `next` is the first run not yet finished.
void keep(const char* chunk, std::uint64_t at, std::uint64_t count, const std::vector<CheckpointRun>& runs, std::size_t& next,
          char* dst, std::size_t entry_bytes) {
  while (next < runs.size() && runs[next].from + runs[next].count <= at) ++next;
  for (std::size_t r = next; r < runs.size() && runs[r].from < at + count; ++r) {
    const std::uint64_t begin = std::max(runs[r].from, at), end = std::min(runs[r].from + runs[r].count, at + count);
    if (begin >= end) continue;
    std::memcpy(dst + (runs[r].to + (begin - runs[r].from)) * entry_bytes, chunk + (begin - at) * entry_bytes,
                (end - begin) * entry_bytes);
  }
}

}  // namespace

std::filesystem::path checkpoint_pieces_dir(const std::filesystem::path& index) {
  return index.parent_path() / kPiecesFolder;
}

std::string checkpoint_piece_name(std::int64_t step, int rank) {
  return "s" + std::to_string(step) + ".p" + std::to_string(rank) + ".bin";
}

std::string checkpoint_piece_file(std::int64_t step, int rank) {
  return std::string(kPiecesFolder) + "/" + checkpoint_piece_name(step, rank);
}

CheckpointPieceRef write_checkpoint_piece(const std::filesystem::path& index, const std::string& file,
                                          const CheckpointPieceOut& piece) {
  // Written from the sections as they are, without copying them into one string (a piece is its
  // rank's state: the copy would double the rank's peak at a checkpoint).
  Writer payload_head;
  payload_head.scalar(kPieceTag);
  payload_head.array(piece.nodes);
  std::uint64_t bonds = 0;
  for (std::size_t k = 1; k < piece.nodes.size(); k += 2) bonds += static_cast<std::uint64_t>(piece.nodes[k]);
  std::vector<std::string> counts;  // each section's byte count, before it
  for (const std::string& section : piece.sections) {
    Writer count;
    count.scalar(static_cast<std::uint64_t>(section.size()));
    counts.push_back(count.bytes());
  }
  std::vector<std::string_view> parts{std::string_view(), payload_head.bytes()};
  for (std::size_t k = 0; k < counts.size(); ++k) parts.push_back(counts[k]), parts.push_back(piece.sections[k]);
  std::uint64_t size = 0, sum = 14695981039346656037ull;
  for (std::size_t k = 1; k < parts.size(); ++k) {
    size += parts[k].size();
    sum = fnv1a(parts[k].data(), parts[k].size(), sum);
  }
  Writer head, tail;
  head.scalar(kCheckpointVersion), head.scalar(kByteOrderMark), head.scalar(size);
  const std::string header = std::string(kMagic, sizeof kMagic) + head.bytes();
  tail.scalar(sum);
  parts[0] = header;
  parts.push_back(tail.bytes());
  std::error_code ec;
  std::filesystem::create_directories(checkpoint_pieces_dir(index), ec);
  if (ec) throw Error(checkpoint_pieces_dir(index).string() + ": cannot create the directory: " + ec.message());
  write_file_atomically(index.parent_path() / file, parts, Durability::synced);
  return {file, piece.nodes.size() / 2, bonds, kHead + size + 8, sum};
}

void write_checkpoint_index(const std::filesystem::path& path, const Checkpoint& index) {
  Writer payload;
  fields(payload, const_cast<Checkpoint&>(index));  // the writer only reads (see fields)
  write_file_atomically(path, framed(payload.bytes()), Durability::synced);
  remove_unnamed_checkpoint_pieces(path, &index);  // earlier checkpoints' pieces
}

void remove_unnamed_checkpoint_pieces(const std::filesystem::path& index, const Checkpoint* named_by) {
  static const std::regex piece_name(R"(s[0-9]+\.p[0-9]+\.bin)");
  const std::filesystem::path folder = checkpoint_pieces_dir(index);
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const std::string file = entry.path().filename().string();
    if (entry.is_symlink(ec) || !entry.is_regular_file(ec) || !std::regex_match(file, piece_name)) continue;
    const std::string name = std::string(kPiecesFolder) + "/" + file;
    bool named = false;
    for (std::size_t k = 0; named_by && k < named_by->pieces.size(); ++k) named = named || named_by->pieces[k].file == name;
    if (!named) std::filesystem::remove(entry.path(), ec);
  }
  std::filesystem::remove(folder, ec);  // only if empty: fails quietly otherwise
}

void read_checkpoint_piece(const std::filesystem::path& index_path, const Checkpoint& index, std::size_t piece,
                           const PieceSelect& select, const std::vector<void*>& dst) {
  const CheckpointPieceRef& ref = index.pieces[piece];
  const std::filesystem::path path = index_path.parent_path() / ref.file;
  const std::string name = path.string();
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw Error(name + ": missing, but " + index_path.string() + " names it as piece " + std::to_string(piece) + " of " +
                      std::to_string(index.pieces.size()) + " (" + ec.message() + ")");
  if (size != ref.bytes)
    throw Error(name + ": " + std::to_string(size) + " bytes, but " + index_path.string() + " names a piece of " +
                std::to_string(ref.bytes) + " bytes (damaged, or of another checkpoint)");
  PieceStream in(path, name);
  if (!in.open()) throw Error(name + ": cannot be opened: " + std::strerror(errno));
  char head[kHead];
  in.raw(head, kHead);
  std::uint32_t version = 0, mark = 0;
  std::uint64_t payload = 0;
  std::memcpy(&version, head + 8, 4), std::memcpy(&mark, head + 12, 4), std::memcpy(&payload, head + 16, 8);
  if (std::memcmp(head, kMagic, sizeof kMagic) != 0 || version != kCheckpointVersion || mark != kByteOrderMark ||
      payload + kHead + 8 != ref.bytes)
    in.fail("its header is not that of a version " + std::to_string(kCheckpointVersion) + " piece of " + std::to_string(ref.bytes) + " bytes");
  in.left_ = payload;
  if (in.scalar<std::uint32_t>() != kPieceTag) in.fail("no piece tag");
  // The nodes, in chunks: the caller keeps what it holds.
  constexpr std::size_t kChunk = 1 << 15;
  CheckpointSelection kept;
  if (in.scalar<std::uint64_t>() != 2 * ref.nodes) in.fail("its node list is not of the " + std::to_string(ref.nodes) + " nodes the index names");
  std::vector<std::int32_t> pairs, global, rows;
  std::uint64_t bond = 0;
  std::int64_t last = -1;
  for (std::uint64_t node = 0; node < ref.nodes; node += kChunk) {
    const std::size_t count = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, ref.nodes - node));
    pairs.resize(2 * count), global.resize(count), rows.resize(count);
    in.read(pairs.data(), pairs.size() * sizeof(std::int32_t));
    const std::uint64_t first_bond = bond;
    for (std::size_t k = 0; k < count; ++k) {
      global[k] = pairs[2 * k], rows[k] = pairs[2 * k + 1];
      if (global[k] <= last || static_cast<std::uint64_t>(global[k]) >= index.nodes || rows[k] < 0)
        in.fail("its nodes are not ascending numbers below " + std::to_string(index.nodes) + " with rows");
      last = global[k];
      bond += static_cast<std::uint64_t>(rows[k]);
    }
    select(node, first_bond, global.data(), rows.data(), count, kept);
  }
  if (bond != ref.bonds) in.fail("its rows hold " + std::to_string(bond) + " bonds, the index names " + std::to_string(ref.bonds));
  std::vector<char> chunk;
  for (std::size_t s = 0; s < index.sections.size(); ++s) {
    const CheckpointSection& section = index.sections[s];
    const std::size_t entry = static_cast<std::size_t>(section.width) * (section.bytes ? 1 : sizeof(double));
    const std::uint64_t entries = section.per_bond ? ref.bonds : ref.nodes;
    if (in.scalar<std::uint64_t>() != entries * entry) in.fail("array '" + section.name + "' is not of the size the index gives it");
    const std::vector<CheckpointRun>& runs = section.per_bond ? kept.bond_runs : kept.node_runs;
    std::size_t next = 0;
    for (std::uint64_t at = 0; at < entries; at += kChunk) {
      const std::uint64_t count = std::min<std::uint64_t>(kChunk, entries - at);
      chunk.resize(static_cast<std::size_t>(count) * entry);
      in.read(chunk.data(), chunk.size());
      if (dst[s]) keep(chunk.data(), at, count, runs, next, static_cast<char*>(dst[s]), entry);
    }
  }
  if (in.left_ != 0) in.fail("its payload has " + std::to_string(in.left_) + " bytes more than its arrays");
  const std::uint64_t computed = in.sum();
  std::uint64_t stored = 0;
  in.raw(&stored, sizeof stored);
  if (stored != computed || computed != ref.checksum)
    throw Error(name + ": checkpoint piece checksum mismatch (the file is damaged, or of another checkpoint than " +
                index_path.string() + ")");
}

// The whole checkpoint's sections, in the order a run writes them (run/state_checkpoint.cpp).
std::vector<CheckpointSection> checkpoint_sections(const std::vector<StateDeclaration>& declared, std::size_t integrator_arrays,
                                                   bool contact) {
  std::vector<CheckpointSection> out;
  for (const char* v : {"u", "v", "f"})
    for (const char* axis : {".x", ".y", ".z"}) out.push_back({std::string(v) + axis, false, false, 1});
  out.push_back({"w", false, false, 1});
  for (const StateDeclaration& d : declared)
    out.push_back({"state:" + d.name, d.extent == StateExtent::per_bond, false, d.components});
  for (std::size_t k = 0; k < integrator_arrays; ++k)
    for (const char* axis : {".x", ".y", ".z"}) out.push_back({"integrator:" + std::to_string(k) + axis, false, false, 1});
  if (contact)
    for (const char* axis : {".x", ".y", ".z"}) out.push_back({std::string("contact_u_build") + axis, false, false, 1});
  out.push_back({"broken", true, true, 1});
  return out;
}


std::uint64_t file_hash(const std::filesystem::path& path) {
  const std::string bytes = read_whole_file(path, "an input file");
  return fnv1a(bytes.data(), bytes.size());
}

namespace {

template <class T>
std::string as_bytes(const std::vector<T>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

}  // namespace

void write_checkpoint(const std::filesystem::path& path, const Checkpoint& checkpoint) {
  Checkpoint index = checkpoint;
  std::vector<StateDeclaration> declared;
  for (const StateArray& a : checkpoint.state_arrays) declared.push_back(a.declaration);
  const bool contact = !checkpoint.contact_u_build[0].empty();
  index.sections = checkpoint_sections(declared, checkpoint.integrator_node_arrays.size(), contact);
  CheckpointPieceOut piece;
  for (std::size_t i = 0; i < checkpoint.nodes; ++i)
    piece.nodes.push_back(static_cast<std::int32_t>(i)), piece.nodes.push_back(checkpoint.row_length.at(i));
  for (const Vec3Array* a : {&checkpoint.state.u, &checkpoint.state.v, &checkpoint.state.f})
    for (const auto& c : *a) piece.sections.push_back(as_bytes(c));
  piece.sections.push_back(as_bytes(checkpoint.state.w));
  for (const StateArray& a : checkpoint.state_arrays) piece.sections.push_back(as_bytes(a.values));
  for (const Vec3Array& a : checkpoint.integrator_node_arrays)
    for (const auto& c : a) piece.sections.push_back(as_bytes(c));
  if (contact)
    for (const auto& c : checkpoint.contact_u_build) piece.sections.push_back(as_bytes(c));
  piece.sections.push_back(as_bytes(checkpoint.broken_flags));
  index.pieces = {write_checkpoint_piece(path, checkpoint_piece_file(checkpoint.loop.step, 0), piece)};
  write_checkpoint_index(path, index);
}

Checkpoint read_checkpoint(const std::filesystem::path& path) {
  Checkpoint c = parse_checkpoint(read_whole_file(path, "the checkpoint"), path.string());
  const std::size_t n = c.nodes;
  // First the rows' lengths of every node, for the whole list's offsets; then the arrays.
  c.row_length.assign(n, 0);
  const std::vector<void*> none(c.sections.size(), nullptr);
  for (std::size_t p = 0; p < c.pieces.size(); ++p)
    read_checkpoint_piece(path, c, p, [&](std::uint64_t, std::uint64_t, const std::int32_t* global, const std::int32_t* rows,
                                          std::size_t count, CheckpointSelection&) {
      for (std::size_t k = 0; k < count; ++k) c.row_length[static_cast<std::size_t>(global[k])] = rows[k];
    }, none);
  std::vector<std::uint64_t> offset(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) offset[i + 1] = offset[i] + static_cast<std::uint64_t>(c.row_length[i]);
  if (offset[n] != c.directed_bonds) throw Error(path.string() + ": not a valid checkpoint: its pieces' rows are not the bonds it names");
  c.state.u = make_vec3(n), c.state.v = make_vec3(n), c.state.f = make_vec3(n), c.state.w.assign(n, 0.0);
  std::vector<void*> dst;
  for (Vec3Array* a : {&c.state.u, &c.state.v, &c.state.f})
    for (auto& comp : *a) dst.push_back(comp.data());
  dst.push_back(c.state.w.data());
  bool contact = false;
  for (const CheckpointSection& s : c.sections) {
    if (s.name.rfind("state:", 0) == 0) {
      StateArray a;
      a.declaration.name = s.name.substr(6);
      a.declaration.extent = s.per_bond ? StateExtent::per_bond : StateExtent::per_node;
      a.declaration.components = s.width;
      a.values.assign((s.per_bond ? offset[n] : n) * static_cast<std::size_t>(s.width), 0.0);
      c.state_arrays.push_back(std::move(a));
    } else if (s.name.rfind("integrator:", 0) == 0 && s.name.size() > 2 && s.name.substr(s.name.size() - 2) == ".x") {
      c.integrator_node_arrays.push_back(make_vec3(n));
    }
    contact = contact || s.name.rfind("contact_u_build", 0) == 0;
  }
  for (StateArray& a : c.state_arrays) dst.push_back(a.values.data());
  for (Vec3Array& a : c.integrator_node_arrays)
    for (auto& comp : a) dst.push_back(comp.data());
  if (contact) {
    c.contact_u_build = make_vec3(n);
    for (auto& comp : c.contact_u_build) dst.push_back(comp.data());
  }
  c.broken_flags.assign(static_cast<std::size_t>(offset[n]), 0);
  dst.push_back(c.broken_flags.data());
  if (dst.size() != c.sections.size())
    throw Error(path.string() + ": not a valid checkpoint: its arrays are not those of a run (" + std::to_string(c.sections.size()) + ")");
  for (std::size_t p = 0; p < c.pieces.size(); ++p)
    read_checkpoint_piece(path, c, p, [&](std::uint64_t first, std::uint64_t first_bond, const std::int32_t* global,
                                          const std::int32_t* rows, std::size_t count, CheckpointSelection& keep) {
      for (std::size_t k = 0; k < count; ++k) {
        const auto g = static_cast<std::size_t>(global[k]);
        keep.node_runs.push_back({first + k, g, 1});
        keep.bond_runs.push_back({first_bond, offset[g], static_cast<std::uint64_t>(rows[k])});
        first_bond += static_cast<std::uint64_t>(rows[k]);
      }
    }, dst);
  return c;
}

Checkpoint parse_checkpoint(const std::string& bytes, const std::string& file) {
  if (bytes.size() < kHead || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw Error(file + ": not a pdsolve checkpoint (no PDCKPT header)");
  Reader head(bytes, sizeof kMagic, kHead, file);
  std::uint32_t version = 0, mark = 0;
  std::uint64_t size = 0;
  head.scalar(version), head.scalar(mark), head.scalar(size);
  if (mark != kByteOrderMark) throw Error(file + ": checkpoint written on a machine of the other byte order");
  if (version != kCheckpointVersion)
    throw Error(file + ": checkpoint format version " + std::to_string(version) + ", this pdsolve reads version " +
                std::to_string(kCheckpointVersion));
  // Named as the header gives it: kHead + size + 8 would wrap around for a size near 2⁶⁴.
  if (size > bytes.size() - kHead || bytes.size() - kHead - size != 8)
    throw Error(file + ": checkpoint truncated or padded: " + std::to_string(bytes.size()) +
                " bytes, the header says a payload of " + std::to_string(size) + " bytes (" +
                std::to_string(kHead + 8) + " more for header and checksum)");
  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + kHead + size, sizeof stored);
  if (stored != fnv1a(bytes.data() + kHead, static_cast<std::size_t>(size)))
    throw Error(file + ": checkpoint checksum mismatch (the file is damaged)");
  Checkpoint c;
  Reader payload(bytes, kHead, kHead + static_cast<std::size_t>(size), file);
  fields(payload, c);
  payload.done();
  std::uint64_t nodes = 0, bonds = 0;
  for (const CheckpointPieceRef& p : c.pieces) nodes += p.nodes, bonds += p.bonds;
  if (nodes != c.nodes || bonds != c.directed_bonds)
    payload.fail("its pieces hold " + std::to_string(nodes) + " nodes and " + std::to_string(bonds) + " bonds, it names " +
                 std::to_string(c.nodes) + " and " + std::to_string(c.directed_bonds));
  if (c.integrator.empty()) payload.fail("no integrator name");
  return c;
}

}  // namespace pd
