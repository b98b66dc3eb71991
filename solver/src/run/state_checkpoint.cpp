// The law's declared state in and out of a checkpoint (run/state_checkpoint.hpp).
#include "run/state_checkpoint.hpp"

#include <string>

#include "core/error.hpp"

namespace pd {

std::vector<StateArray> checkpointed_state(const Model& model) {
  std::vector<StateArray> out;
  for (const StateArray& a : model.state_arrays.all())
    if (a.declaration.checkpoint) out.push_back(a);
  return out;
}

bool fits_checkpointed_state(const std::vector<StateArray>& saved, const Model& model, std::size_t nodes,
                             std::size_t directed) {
  std::size_t k = 0;
  for (const StateArray& a : model.state_arrays.all()) {
    const StateDeclaration& d = a.declaration;
    if (!d.checkpoint) continue;
    if (k == saved.size()) return false;
    const StateDeclaration& s = saved[k].declaration;
    if (s.name != d.name || s.extent != d.extent || s.components != d.components ||
        saved[k].values.size() != StateArrays::size_of(d, nodes, directed))
      return false;
    ++k;
  }
  return k == saved.size();
}

void restore_checkpointed_state(std::vector<StateArray> saved, Model& whole) {
  StateArrays by_name;
  by_name.all() = std::move(saved);
  for (StateArray& a : whole.state_arrays.all()) {
    StateArray* from = by_name.find(a.declaration.name);
    if (!from || !a.declaration.checkpoint) continue;
    if (a.declaration.extent == StateExtent::per_node || !whole.bonds.neighbour.empty()) a.values = std::move(from->values);
  }
}

namespace {

template <class T>
std::string bytes_of(const T* data, std::size_t count) {
  return std::string(reinterpret_cast<const char*>(data), count * sizeof(T));
}

// The owned local nodes in ascending order: the piece's, or every node of a serial run.
std::vector<std::int32_t> owned_nodes(const Model& local, const LocalPiece* piece) {
  if (piece) return piece->owned_local;
  std::vector<std::int32_t> all(local.nodes.size());
  for (std::size_t l = 0; l < all.size(); ++l) all[l] = static_cast<std::int32_t>(l);
  return all;
}

std::int32_t global_of(const LocalPiece* piece, std::size_t l) {
  return piece ? piece->global[l] : static_cast<std::int32_t>(l);
}

}  // namespace

std::vector<CheckpointSection> checkpoint_sections_of(const Model& local, std::size_t integrator_arrays, bool contact) {
  std::vector<StateDeclaration> declared;
  for (const StateArray& a : checkpointed_state(local)) declared.push_back(a.declaration);
  return checkpoint_sections(declared, integrator_arrays, contact);
}

CheckpointPieceOut checkpoint_piece_of(const Model& local, const LocalPiece* piece, const State& state,
                                       const std::vector<Vec3Array*>& integrator_arrays, const Vec3Array* contact_u_build) {
  const std::vector<std::int32_t> owned = owned_nodes(local, piece);
  const BondList& b = local.bonds;
  CheckpointPieceOut out;
  for (std::int32_t l : owned) {
    const auto q = static_cast<std::size_t>(l);
    out.nodes.push_back(global_of(piece, q));
    out.nodes.push_back(static_cast<std::int32_t>(b.offsets[q + 1] - b.offsets[q]));
  }
  // Per node: the owned entries, `width` values each. Per bond: the owned rows, which are the
  // local list's rows in order (a ghost's row is empty), so the local array as it is.
  auto per_node = [&](const double* values, int width) {
    std::string bytes;
    bytes.reserve(owned.size() * static_cast<std::size_t>(width) * sizeof(double));
    for (std::int32_t l : owned) bytes += bytes_of(values + static_cast<std::size_t>(l) * width, static_cast<std::size_t>(width));
    out.sections.push_back(std::move(bytes));
  };
  for (const Vec3Array* a : {&state.u, &state.v, &state.f})
    for (const auto& c : *a) per_node(c.data(), 1);
  per_node(state.w.data(), 1);
  for (const StateArray& a : local.state_arrays.all()) {
    if (!a.declaration.checkpoint) continue;
    if (a.declaration.extent == StateExtent::per_node) per_node(a.values.data(), a.declaration.components);
    else out.sections.push_back(bytes_of(a.values.data(), a.values.size()));
  }
  for (const Vec3Array* a : integrator_arrays)
    for (const auto& c : *a) per_node(c.data(), 1);
  if (contact_u_build)
    for (const auto& c : *contact_u_build) per_node(c.data(), 1);
  out.sections.push_back(bytes_of(b.broken.data(), b.broken.size()));
  return out;
}

void restore_from_pieces(const std::filesystem::path& index_path, const Checkpoint& index, Model& local,
                         const LocalPiece* piece, State& state, const std::vector<Vec3Array*>& integrator_arrays,
                         Vec3Array* contact_u_build, BondList* whole_rows) {
  const std::size_t n = local.nodes.size();
  BondList& b = local.bonds;
  std::vector<void*> dst;
  for (Vec3Array* a : {&state.u, &state.v, &state.f})
    for (auto& c : *a) dst.push_back(c.data());
  dst.push_back(state.w.data());
  for (StateArray& a : local.state_arrays.all())
    if (a.declaration.checkpoint) dst.push_back(a.values.data());
  for (Vec3Array* a : integrator_arrays)
    for (auto& c : *a) {
      if (c.size() != n) throw Error(index_path.string() + ": the integrator's arrays are not sized to the model (a bug here)");
      dst.push_back(c.data());
    }
  if (contact_u_build) {
    *contact_u_build = make_vec3(n);
    for (auto& c : *contact_u_build) dst.push_back(c.data());
  }
  dst.push_back(b.broken.data());
  if (dst.size() != index.sections.size()) throw Error(index_path.string() + ": its arrays are not this run's");
  std::size_t nodes_found = 0, rows_found = 0;
  const std::size_t owned = piece ? piece->owned_local.size() : n;
  const std::string misfit = ": does not fit this model (a row's length differs); restart with the case and node file it was written for";
  for (std::size_t k = 0; k < index.pieces.size(); ++k) {
    std::size_t cursor = 0;  // the next local node, by ascending global number, not yet matched
    read_checkpoint_piece(index_path, index, k, [&](std::uint64_t first, std::uint64_t first_bond, const std::int32_t* global,
                                                    const std::int32_t* rows, std::size_t count, CheckpointSelection& keep) {
      for (std::size_t j = 0; j < count; ++j) {
        const std::uint64_t bonds_here = static_cast<std::uint64_t>(rows[j]);
        while (cursor < n && global_of(piece, cursor) < global[j]) ++cursor;
        if (cursor < n && global_of(piece, cursor) == global[j]) {
          keep.node_runs.push_back({first + j, cursor, 1});
          ++nodes_found;
          if (!piece || piece->owned[cursor]) {
            if (static_cast<std::uint64_t>(b.offsets[cursor + 1] - b.offsets[cursor]) != bonds_here)
              throw Error((index_path.parent_path() / index.pieces[k].file).string() + misfit);
            keep.bond_runs.push_back({first_bond, static_cast<std::uint64_t>(b.offsets[cursor]), bonds_here});
            ++rows_found;
          }
        }
        first_bond += bonds_here;
      }
    }, dst);
  }
  if (nodes_found != n || rows_found != owned)
    throw Error(index_path.string() + ": its pieces hold " + std::to_string(nodes_found) + " of this rank's " + std::to_string(n) +
                " nodes; a piece is missing from the index or of another checkpoint");
  if (!whole_rows) return;
  // The whole list's flags too (a decomposed run that holds it): every row, from every piece.
  std::vector<void*> broken_only(index.sections.size(), nullptr);
  broken_only.back() = whole_rows->broken.data();
  for (std::size_t k = 0; k < index.pieces.size(); ++k)
    read_checkpoint_piece(index_path, index, k, [&](std::uint64_t, std::uint64_t first_bond, const std::int32_t* global,
                                                    const std::int32_t* rows, std::size_t count, CheckpointSelection& keep) {
      for (std::size_t j = 0; j < count; ++j) {
        const auto g = static_cast<std::size_t>(global[j]);
        if (whole_rows->offsets[g + 1] - whole_rows->offsets[g] != rows[j])
          throw Error((index_path.parent_path() / index.pieces[k].file).string() + misfit);
        keep.bond_runs.push_back({first_bond, static_cast<std::uint64_t>(whole_rows->offsets[g]), static_cast<std::uint64_t>(rows[j])});
        first_bond += static_cast<std::uint64_t>(rows[j]);
      }
    }, broken_only);
}

}  // namespace pd
