// A checkpoint: out/<case>/checkpoint.bin, the index, and its pieces in out/<case>/checkpoint.pieces/:
// everything the time loop needs to continue a run bitwise as if it had never stopped
// (pipeline/formats.md §5). Each rank writes its own piece (its owned nodes' state and its owned
// rows' bond state, in ascending global node order); rank 0 writes the index last, naming every
// piece with its size and checksum, so no rank ever holds the whole model's state for it (issue 37).
// A serial run is one piece. A restart on any rank count streams the pieces and keeps what it holds.
//
// Both files (little-endian): 8 bytes magic "PDCKPT\r\n", uint32 format version (kCheckpointVersion),
// uint32 byte-order mark 0x01020304, uint64 payload size, the payload, then uint64 FNV-1a-64 of
// the payload. A payload is a fixed sequence of scalars and arrays (an array: uint64 count, then
// the raw elements). The index's: the fields of Checkpoint below but the arrays (`sections` names
// them), then the pieces. A piece's: a uint32 tag "PIEC", its owned nodes as int32 pairs (global
// number, row length; ascending), then per section in the index's order a uint64 byte count and
// the values.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/nodes.hpp"
#include "core/state_arrays.hpp"
#include "core/state.hpp"
#include "run/loop_state.hpp"

namespace pd {

// 2: the per-node critical stretch of LAMMPS's α rule after the broken flags (docs/lammps.md).
// 3: the indenter energy apart from the contact energy. 4: the linear solver in use (issue 36).
// 5: the law's declared state by name in place of the per-node critical stretch, and the force
// terms' energies as one list (issue 37). 6: an index and one piece per rank (issue 37, item 3).
constexpr std::uint32_t kCheckpointVersion = 6;

// One array of the pieces: per owned node or per directed bond of the owned rows, `width` values
// each, doubles or (the broken flags) bytes. Names: u.x … f.z, w, state:<declared name>,
// integrator:<k>.x …, contact_u_build.x …, broken.
struct CheckpointSection {
  std::string name;
  bool per_bond = false;
  bool bytes = false;
  int width = 1;
  bool operator==(const CheckpointSection& o) const {
    return name == o.name && per_bond == o.per_bond && bytes == o.bytes && width == o.width;
  }
};

// A piece as the index names it: its file (relative to the index's folder), what it holds, and
// its size and checksum, checked by the reader (a piece of another checkpoint is refused).
struct CheckpointPieceRef {
  std::string file;
  std::uint64_t nodes = 0, bonds = 0;  // owned nodes, directed bonds of their rows
  std::uint64_t bytes = 0, checksum = 0;
};

struct Checkpoint {
  // What it belongs to: a restart refuses a checkpoint of another case or node file.
  std::uint64_t case_hash = 0;   // FNV-1a-64 of the case.json bytes
  std::uint64_t nodes_hash = 0;  // FNV-1a-64 of the node-file bytes
  std::uint64_t nodes = 0, directed_bonds = 0;
  std::string integrator;

  // The time loop (run/loop.cpp), whole; in the file in the order of its fields.
  LoopState loop;
  std::vector<char> integrator_state;  // Integrator::save_state()

  // The run's totals (State::copy_totals) in the index; below them, the whole model's arrays as
  // read_checkpoint assembles them from the pieces (a restart never does: run/state_checkpoint.hpp).
  State state;
  std::vector<std::uint8_t> broken_flags;  // BondList::broken
  std::vector<std::int32_t> row_length;    // bonds per node's row (write_checkpoint needs it)
  std::vector<Vec3Array> integrator_node_arrays;  // Integrator::checkpointed_node_arrays()
  // Model::state_arrays' arrays with `checkpoint`, in declaration order, in the whole model's node
  // and bond order. In the file: their count, then each one's name, extent (0 per node, 1 per
  // bond), components and values; the other fields of a declaration are the law's, not the file's.
  std::vector<StateArray> state_arrays;

  // The contact Verlet list: rebuilt at restart from the displacement of its last build.
  std::int64_t contact_rebuilds = 0;
  double contact_seconds = 0.0;
  Vec3Array contact_u_build;

  // Output: the frames written so far (their times; file k is frames/frame_k.vtu) and the length
  // of history.csv at the checkpoint (rows after it, from a run killed later, are cut off).
  std::vector<double> frame_times;
  std::uint64_t history_bytes = 0;

  // Integrator::linear_solver() ("direct", "cg block_jacobi", "cg amg"; "" for a scheme without
  // one): auto's choice depends on the rank count, and a restart keeps it where it can (run/start.cpp).
  std::string linear_solver;
  // The frames written so far are in pieces (a .pvtu each): a restart goes on so (run/start.cpp).
  bool frames_in_pieces = false;

  // The index's list of the pieces' arrays and the pieces themselves.
  std::vector<CheckpointSection> sections;
  std::vector<CheckpointPieceRef> pieces;
};

// Where the pieces go: <index>'s folder / checkpoint.pieces / s<step>.p<rank>.bin, named by the
// step so that writing a new checkpoint never touches the pieces the current index names.
std::filesystem::path checkpoint_pieces_dir(const std::filesystem::path& index);
std::string checkpoint_piece_name(std::int64_t step, int rank);
// Deletes the pieces in checkpoint_pieces_dir(index) that `index` does not name (all of them when
// null: a fresh run), then the folder if nothing else is in it. Only regular files named as
// checkpoint_piece_name names them go: anything else there is not the solver's to delete.
void remove_unnamed_checkpoint_pieces(const std::filesystem::path& index, const Checkpoint* named_by);
// checkpoint.pieces/<checkpoint_piece_name>: the piece's file relative to the index's folder.
std::string checkpoint_piece_file(std::int64_t step, int rank);

// The sections of a run's pieces, in order: u.x … f.z, w, the declared state with `checkpoint`
// (`declared`, in declaration order), the integrator's per-node arrays, contact's u_build (if
// `contact`: a contact list was built), broken.
std::vector<CheckpointSection> checkpoint_sections(const std::vector<StateDeclaration>& declared, std::size_t integrator_arrays,
                                                   bool contact);

// A piece to write: the owned nodes' global numbers (ascending) and row lengths, and per section
// (in order) its values as bytes.
struct CheckpointPieceOut {
  std::vector<std::int32_t> nodes;  // pairs: global number, row length
  std::vector<std::string> sections;
};
// Written atomically and synced (io/atomic_file); returns its reference for the index (file: the
// name relative to the index's folder).
// `file`: checkpoint_piece_file's.
CheckpointPieceRef write_checkpoint_piece(const std::filesystem::path& index, const std::string& file,
                                          const CheckpointPieceOut& piece);
// The index, atomically and synced, once every piece it names is on disk; then the pieces of
// other checkpoints in checkpoint.pieces/ go.
void write_checkpoint_index(const std::filesystem::path& path, const Checkpoint& index);

// What a reader keeps of a piece: runs of entries, sorted by their place in the piece.
struct CheckpointRun {
  std::uint64_t from, to, count;  // entries [from, from + count) of the piece → [to, to + count) of the reader's array
};
struct CheckpointSelection {
  std::vector<CheckpointRun> node_runs, bond_runs;
};
// Called with the piece's nodes in chunks, in order: `count` nodes from the piece's node
// `first_node` and bond `first_bond` on, global[k] and row_length[k] each; adds to `keep`.
using PieceSelect = std::function<void(std::uint64_t first_node, std::uint64_t first_bond, const std::int32_t* global,
                                       const std::int32_t* row_length, std::size_t count, CheckpointSelection& keep)>;
// Streams one piece (in chunks, never whole): checks its header, size and checksum against the
// index's reference and its arrays against the index's sections; `select` chooses the entries
// kept, `dst[s]` receives section s (doubles or bytes as declared; null: skipped). Throws pd::Error
// naming the piece's file.
void read_checkpoint_piece(const std::filesystem::path& index_path, const Checkpoint& index, std::size_t piece,
                           const PieceSelect& select, const std::vector<void*>& dst);


// FNV-1a-64 of a file's bytes; throws pd::Error if it cannot be read.
std::uint64_t file_hash(const std::filesystem::path& path);

// A whole checkpoint in one piece (tests and tools; a run writes its pieces itself, run/state_checkpoint).
void write_checkpoint(const std::filesystem::path& path, const Checkpoint& checkpoint);

// The index and every piece assembled into the whole model's arrays (tests and tools: a restart
// streams the pieces instead). Throws pd::Error naming the file if it is not a checkpoint of this
// version, is truncated, or its checksum does not match.
Checkpoint read_checkpoint(const std::filesystem::path& path);

// The index alone from its bytes (`file` only names it in messages); the fuzz targets call this.
Checkpoint parse_checkpoint(const std::string& bytes, const std::string& file);

}  // namespace pd
