// Writer and reader of checkpoint.bin (io/checkpoint.hpp, pipeline/formats.md §5).
#include "io/checkpoint.hpp"

#include "io/read_file.hpp"

#include <cstring>
#include <fstream>
#include <iterator>
#include <type_traits>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/vtu.hpp"

namespace pd {

namespace {

constexpr char kMagic[8] = {'P', 'D', 'C', 'K', 'P', 'T', '\r', '\n'};
constexpr std::uint32_t kByteOrderMark = 0x01020304;

std::uint64_t fnv1a(const char* data, std::size_t size) {
  std::uint64_t h = 14695981039346656037ull;
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

// The declared state: the arrays' count, then per array its name, extent, components and values.
template <class IO>
void declared_state(IO& io, std::vector<StateArray>& arrays) {
  auto count = static_cast<std::uint64_t>(arrays.size());
  io.scalar(count);
  if constexpr (std::is_same_v<IO, Reader>) {
    if (count > 1024) io.fail("more declared state arrays than any law declares (" + std::to_string(count) + ")");
    arrays.resize(static_cast<std::size_t>(count));
  }
  for (StateArray& a : arrays) {
    StateDeclaration& d = a.declaration;
    text(io, d.name);
    auto extent = static_cast<std::uint8_t>(d.extent);
    auto components = static_cast<std::int32_t>(d.components);
    io.scalar(extent), io.scalar(components);
    io.array(a.values);
    if constexpr (std::is_same_v<IO, Reader>) {
      if (extent > 1) io.fail("declared state '" + d.name + "' is neither per node nor per bond");
      if (components < 1 || a.values.size() % static_cast<std::size_t>(components) != 0)
        io.fail("declared state '" + d.name + "' has no whole entries");
      d.extent = static_cast<StateExtent>(extent);
      d.components = components;
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
  io.vec3(s.u), io.vec3(s.v), io.vec3(s.f), io.array(s.w);
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
  io.array(c.broken_flags);
  declared_state(io, c.state_arrays);  // version 5 (version 2 to 4: LAMMPS's s0 alone)
  io.scalar(c.contact_rebuilds), io.scalar(c.contact_seconds), io.vec3(c.contact_u_build);
  io.array(c.frame_times), io.scalar(c.history_bytes);
  text(io, c.linear_solver);     // version 4 (issue 36)
}

}  // namespace

std::uint64_t file_hash(const std::filesystem::path& path) {
  const std::string bytes = read_whole_file(path, "an input file");
  return fnv1a(bytes.data(), bytes.size());
}

void write_checkpoint(const std::filesystem::path& path, const Checkpoint& checkpoint) {
  Writer payload;
  fields(payload, const_cast<Checkpoint&>(checkpoint));  // the writer only reads (see fields)
  Writer file;
  std::string text(kMagic, sizeof kMagic);
  file.scalar(kCheckpointVersion);
  file.scalar(kByteOrderMark);
  file.scalar(static_cast<std::uint64_t>(payload.bytes().size()));
  text += file.bytes();
  text += payload.bytes();
  Writer sum;
  sum.scalar(fnv1a(payload.bytes().data(), payload.bytes().size()));
  text += sum.bytes();
  write_file_atomically(path, text, Durability::synced);
}

Checkpoint read_checkpoint(const std::filesystem::path& path) {
  return parse_checkpoint(read_whole_file(path, "the checkpoint"), path.string());
}

Checkpoint parse_checkpoint(const std::string& bytes, const std::string& file) {
  constexpr std::size_t kHead = sizeof kMagic + 4 + 4 + 8;
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
  const std::size_t n = c.state.u[0].size();
  for (const auto* a : {&c.state.u, &c.state.v, &c.state.f})
    for (const auto& comp : *a)
      if (comp.size() != n) payload.fail("arrays of different lengths");
  if (c.state.w.size() != n || c.nodes != n) payload.fail("arrays of different lengths");
  for (const auto& comp : c.contact_u_build)
    if (comp.size() != c.contact_u_build[0].size() || (!comp.empty() && comp.size() != n))
      payload.fail("arrays of different lengths");
  if (c.integrator.empty()) payload.fail("no integrator name");
  return c;
}

}  // namespace pd
