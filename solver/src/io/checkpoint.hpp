// The checkpoint file out/<case>/checkpoint.bin: everything the time loop needs to continue a run
// bitwise as if it had never stopped (pipeline/formats.md §5).
//
// Layout (little-endian): 8 bytes magic "PDCKPT\r\n", uint32 format version (kCheckpointVersion),
// uint32 byte-order mark 0x01020304, uint64 payload size, the payload, then uint64 FNV-1a-64 of
// the payload. The payload is a fixed sequence of scalars and arrays (an array: uint64 count,
// then the raw elements), in the order of the fields of Checkpoint below.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
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
// terms' energies as one list (issue 37).
constexpr std::uint32_t kCheckpointVersion = 5;

struct Checkpoint {
  // What it belongs to: a restart refuses a checkpoint of another case or node file.
  std::uint64_t case_hash = 0;   // FNV-1a-64 of the case.json bytes
  std::uint64_t nodes_hash = 0;  // FNV-1a-64 of the node-file bytes
  std::uint64_t nodes = 0, directed_bonds = 0;
  std::string integrator;

  // The time loop (run/loop.cpp), whole; in the file in the order of its fields.
  LoopState loop;
  std::vector<char> integrator_state;  // Integrator::save_state()

  State state;
  std::vector<std::uint8_t> broken_flags;  // BondList::broken
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
};

// FNV-1a-64 of a file's bytes; throws pd::Error if it cannot be read.
std::uint64_t file_hash(const std::filesystem::path& path);

// Writes under a temporary name and renames into place: a checkpoint is whole or absent.
void write_checkpoint(const std::filesystem::path& path, const Checkpoint& checkpoint);

// Throws pd::Error naming the file if it is not a checkpoint of this version, is truncated, or its
// checksum does not match.
Checkpoint read_checkpoint(const std::filesystem::path& path);

// The same from the file's bytes (`file` only names it in messages); the fuzz targets call this.
Checkpoint parse_checkpoint(const std::string& bytes, const std::string& file);

}  // namespace pd
