// Declared state (issue 37, item 2): the arrays a material keeps from one force evaluation to the
// next — a history — declared once, per node or per bond, with what the run does with each.
//
// A law says what it keeps (BondModel::state_declarations) and fills it at rest
// (BondModel::initialise_state); the model holds the values (Model::state_arrays), and the parts of
// the run that must carry a history iterate over the declarations instead of naming the arrays:
//   - the checkpoint (io/checkpoint) writes and restores every array with `checkpoint`;
//   - a decomposed run's halo (operator/force_operator) refreshes the ghosts' entries of every
//     per-node array with `halo` before each breaking pass, in the same exchange as u;
//   - mixed's rollback (integrators/mixed) puts back every array with `rollback` when a quasi-static
//     try is abandoned, as it puts back the broken flags;
//   - the frame writer (io/output) writes every per-node array with `frames` as point data.
// So a material with history (LAMMPS's per-node critical stretch, a plastic stretch per bond) is its
// folder, its test file and its schema entry.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pd {

// Where an array's entries live: one row of `components` values per node, or per directed bond (in
// the bond list's order: a bond's two copies are two entries, as its broken flags).
enum class StateExtent : std::uint8_t { per_node = 0, per_bond = 1 };

struct StateDeclaration {
  std::string name;  // unique in the model; a frame's point-data name
  StateExtent extent = StateExtent::per_node;
  int components = 1;
  double initial = 0.0;  // every entry's value before the law's initialise_state
  bool checkpoint = true;  // written to checkpoint.bin and read back on a restart
  // A decomposed run: the ghosts' entries are their owners' before a breaking pass (the pass reads a
  // bond's far end). Per node only: a ghost has no bonds of its own.
  bool halo = false;
  bool rollback = true;  // put back when a quasi-static try is abandoned (integrators/mixed)
  bool frames = false;   // written to every frame as point data. Per node only: frames hold nodes.
};

// One declared array and its values.
struct StateArray {
  StateDeclaration declaration;
  std::vector<double> values;  // entries × components, entry e's at components·e …
};

class StateArrays {
 public:
  StateArrays() = default;
  // Every declaration's array, sized for `nodes` nodes and `bonds` directed bonds and filled with
  // its initial value. Throws pd::Error for a name declared twice, components < 1, or a per-bond
  // array declared for the halo or the frames (see StateDeclaration).
  StateArrays(const std::vector<StateDeclaration>& declarations, std::size_t nodes, std::size_t bonds);

  bool empty() const { return arrays_.empty(); }
  std::vector<StateArray>& all() { return arrays_; }
  const std::vector<StateArray>& all() const { return arrays_; }
  // The array named `name`, or null when no law declared it.
  StateArray* find(const std::string& name);
  const StateArray* find(const std::string& name) const;

  // How many values an array of `d` holds for `nodes` nodes and `bonds` directed bonds.
  static std::size_t size_of(const StateDeclaration& d, std::size_t nodes, std::size_t bonds);

  // The values of every array with `rollback`, in declaration order: what restore_rollback puts back.
  std::vector<std::vector<double>> save_rollback() const;
  void restore_rollback(const std::vector<std::vector<double>>& saved);

  // Bytes held (for the memory lines of run.log).
  std::int64_t bytes() const;

 private:
  std::vector<StateArray> arrays_;
};

}  // namespace pd
