// One rank's piece of the model: owned nodes, ghosts, local rows (parallel/local_model.hpp).
#include "parallel/local_model.hpp"

#include <algorithm>
#include <string>

#include "core/error.hpp"

namespace pd {

namespace {

template <class T>
std::vector<T> pick(const std::vector<T>& a, const std::vector<std::int32_t>& global) {
  std::vector<T> out(global.size());
  for (std::size_t l = 0; l < global.size(); ++l) out[l] = a[static_cast<std::size_t>(global[l])];
  return out;
}

// `width` values per entry: entry global[l]'s of `a` for every l.
std::vector<double> pick_rows(const std::vector<double>& a, const std::vector<std::int32_t>& global, int width) {
  const auto w = static_cast<std::size_t>(width);
  std::vector<double> out(global.size() * w);
  for (std::size_t l = 0; l < global.size(); ++l)
    std::copy_n(a.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(global[l]) * w), w, out.begin() + static_cast<std::ptrdiff_t>(l * w));
  return out;
}

// A list of global node numbers → the local numbers of those this rank owns, in the same order.
std::vector<std::int32_t> owned_only(const std::vector<std::int32_t>& nodes, const std::vector<std::int32_t>& local_of,
                                     const std::vector<std::int32_t>& owner, int rank) {
  std::vector<std::int32_t> out;
  for (std::int32_t g : nodes)
    if (owner[static_cast<std::size_t>(g)] == rank) out.push_back(local_of[static_cast<std::size_t>(g)]);
  return out;
}

// The piece from g's per-node data and the rows of the owned nodes: owned node i's row is rows'
// row row_of(i) (neighbours numbered globally). g's own bond list is not read.
template <class RowOf>
LocalPiece make_piece(const Model& g, const std::vector<std::int32_t>& owner, int rank, const BondList& rows, RowOf row_of,
                      BondList* take = nullptr) {
  const std::size_t n = g.nodes.size();
  LocalPiece p;
  p.rank = rank;
  p.global_nodes = static_cast<std::int64_t>(n);
  // Owned nodes and their bond partners (broken bonds too: the set never changes during a run).
  std::vector<std::uint8_t> wanted(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (owner[i] != rank) continue;
    wanted[i] = 1;
    const std::size_t r = row_of(i);
    for (std::int64_t k = rows.offsets[r]; k < rows.offsets[r + 1]; ++k)
      wanted[static_cast<std::size_t>(rows.neighbour[static_cast<std::size_t>(k)])] = 1;
  }
  std::vector<std::int32_t> local_of(n, -1);
  for (std::size_t i = 0; i < n; ++i)
    if (wanted[i]) {
      local_of[i] = static_cast<std::int32_t>(p.global.size());
      p.owned.push_back(owner[i] == rank ? 1 : 0);
      (owner[i] == rank ? p.owned_local : p.ghost_local).push_back(local_of[i]);
      p.global.push_back(static_cast<std::int32_t>(i));
    }
  const std::size_t nl = p.global.size();

  Model& m = p.model;
  m.horizon = g.horizon;
  m.grid_spacing = g.grid_spacing;
  m.damping = g.damping;
  m.material = g.material;
  m.block_materials = g.block_materials;  // a law made on the piece reads them (LPS's moduli)
  m.analysis = g.analysis;
  m.thickness = g.thickness;
  m.contact = g.contact;
  m.indenters = g.indenters;
  m.density = pick(g.density, p.global);
  m.block_index = pick(g.block_index, p.global);
  m.no_fail = pick(g.no_fail, p.global);
  m.break_after_force = g.break_after_force;
  m.nodes.dimension = g.nodes.dimension;
  m.nodes.grid_spacing = g.nodes.grid_spacing;
  for (int d = 0; d < 3; ++d) m.nodes.x[static_cast<std::size_t>(d)] = pick(g.nodes.x[static_cast<std::size_t>(d)], p.global);
  m.nodes.volume = pick(g.nodes.volume, p.global);
  m.nodes.block = pick(g.nodes.block, p.global);
  for (const NodeSet& set : g.nodes.sets) m.nodes.sets.push_back(NodeSet{set.name, pick(set.member, p.global)});

  // Owned rows in the global order of their neighbours (local_of is increasing, so a row stays
  // ascending); a ghost's row is empty.
  m.bonds.volume_weight = g.bonds.volume_weight;
  // The split correction's moduli factors, per node (the piece's LPS law copies its moduli from the
  // whole model's anyway, when there is one: LpsModel::for_piece).
  for (std::size_t l = 0; l < nl && !g.bonds.surface_moduli.empty(); ++l)
    for (std::size_t q = 0; q < 2; ++q)
      m.bonds.surface_moduli.push_back(g.bonds.surface_moduli[2 * static_cast<std::size_t>(p.global[l]) + q]);
  m.bonds.offsets.assign(nl + 1, 0);
  if (take) {
    // The owned rows, ascending by node, are in local order too (a ghost's row between them is
    // empty): the piece takes their arrays and renumbers the neighbours in place, so the rows are
    // never held twice (the peak memory of a rank that builds only its rows).
    for (std::size_t l = 0; l < nl; ++l) {
      std::int64_t length = 0;
      if (p.owned[l]) {
        const std::size_t r = row_of(static_cast<std::size_t>(p.global[l]));
        length = rows.offsets[r + 1] - rows.offsets[r];
      }
      m.bonds.offsets[l + 1] = m.bonds.offsets[l] + length;
    }
    m.bonds.neighbour = std::move(take->neighbour);
    for (std::int32_t& j : m.bonds.neighbour) j = local_of[static_cast<std::size_t>(j)];
    m.bonds.broken = std::move(take->broken);
    m.bonds.surface_factor = std::move(take->surface_factor);
    *take = BondList{};
  } else {
    std::size_t owned_bonds = 0;
    for (std::size_t l = 0; l < nl; ++l)
      if (p.owned[l]) owned_bonds += static_cast<std::size_t>(rows.offsets[row_of(static_cast<std::size_t>(p.global[l])) + 1] -
                                                              rows.offsets[row_of(static_cast<std::size_t>(p.global[l]))]);
    m.bonds.neighbour.reserve(owned_bonds);  // exactly: no vector's doubling slack in the peak memory
    m.bonds.broken.reserve(owned_bonds);
    if (rows.corrected()) m.bonds.surface_factor.reserve(owned_bonds);
    for (std::size_t l = 0; l < nl; ++l) {
      const auto i = static_cast<std::size_t>(p.global[l]);
      if (p.owned[l]) {
        const std::size_t r = row_of(i);
        for (std::int64_t k = rows.offsets[r]; k < rows.offsets[r + 1]; ++k) {
          m.bonds.neighbour.push_back(local_of[static_cast<std::size_t>(rows.neighbour[static_cast<std::size_t>(k)])]);
          m.bonds.broken.push_back(rows.broken[static_cast<std::size_t>(k)]);
          // The surface-correction factors were computed on the whole model (core/model.cpp): the serial bits.
          if (rows.corrected()) m.bonds.surface_factor.push_back(rows.surface_factor[static_cast<std::size_t>(k)]);
        }
      }
      m.bonds.offsets[l + 1] = static_cast<std::int64_t>(m.bonds.neighbour.size());
    }
  }

  // Conditions act on owned nodes only: a ghost's motion is its owner's.
  for (const PrescribedMotion& pm : g.conditions.prescribed) {
    PrescribedMotion local = pm;
    local.nodes = owned_only(pm.nodes, local_of, owner, rank);
    m.conditions.prescribed.push_back(std::move(local));
  }
  for (const BodyForce& bf : g.conditions.body_forces) {
    BodyForce local = bf;
    local.nodes = owned_only(bf.nodes, local_of, owner, rank);
    m.conditions.body_forces.push_back(std::move(local));
  }
  for (int d = 0; d < 3; ++d)
    if (g.conditions.fixed[static_cast<std::size_t>(d)].size() == n)
      m.conditions.fixed[static_cast<std::size_t>(d)] = pick(g.conditions.fixed[static_cast<std::size_t>(d)], p.global);

  // The law for the piece (materials/bond_model.hpp for_piece): by default built again from the
  // registry on the local model; a law whose per-node constants need whole rows copies them from
  // the whole model's law, or, made on a skeleton, has the owned rows' and the piece's maker fills
  // the ghosts' (BondModel::set_decomposed).
  m.bond_model = g.bond_model->for_piece(m, p.global, material_registry().get(g.bond_model->name()).make);
  // The law's history (core/state_arrays.hpp) as the whole model holds it: per node, the local
  // nodes' entries (a ghost's are copies that the operator refreshes from their owners before each
  // breaking pass, for an array with `halo`); per bond, the owned rows'. A whole model that holds no
  // rows (take) leaves the piece's at their initial value, for its maker to fill from the rows.
  declare_state(m, false);
  for (StateArray& a : m.state_arrays.all()) {
    const StateArray* whole = g.state_arrays.find(a.declaration.name);
    if (!whole) continue;
    if (a.declaration.extent == StateExtent::per_node) a.values = pick_rows(whole->values, p.global, a.declaration.components);
    else if (!take) a.values = rows_to_local(p, g.bonds, whole->values, m.bonds, a.declaration.components);
  }
  return p;
}

}  // namespace

LocalPiece make_local_piece(const Model& g, const std::vector<std::int32_t>& owner, int rank) {
  return make_piece(g, owner, rank, g.bonds, [](std::size_t i) { return i; });
}

LocalPiece make_local_piece(const Model& g, const std::vector<std::int32_t>& owner, int rank, BondList owned_rows) {
  // Owned node i's row: its place among the owned nodes (ascending, as build_bond_rows was given them).
  std::vector<std::int32_t> row(g.nodes.size(), -1);
  std::int32_t next = 0;
  for (std::size_t i = 0; i < owner.size(); ++i)
    if (owner[i] == rank) row[i] = next++;
  if (static_cast<std::size_t>(next) + 1 != owned_rows.offsets.size())
    throw Error("make_local_piece: " + std::to_string(owned_rows.offsets.size() - 1) + " rows given for " +
                std::to_string(next) + " owned nodes");
  return make_piece(g, owner, rank, owned_rows, [&row](std::size_t i) { return static_cast<std::size_t>(row[i]); },
                    &owned_rows);
}

std::vector<double> to_local(const LocalPiece& piece, const std::vector<double>& a) { return pick(a, piece.global); }

std::vector<double> rows_to_local(const LocalPiece& piece, const BondList& global, const std::vector<double>& per_bond,
                                  const BondList& local, int width) {
  const auto w = static_cast<std::size_t>(width);
  std::vector<double> out(static_cast<std::size_t>(local.offsets.back()) * w, 0.0);
  for (std::int32_t l : piece.owned_local) {
    const auto i = static_cast<std::size_t>(piece.global[static_cast<std::size_t>(l)]);
    std::copy(per_bond.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(global.offsets[i]) * w),
              per_bond.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(global.offsets[i + 1]) * w),
              out.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(local.offsets[static_cast<std::size_t>(l)]) * w));
  }
  return out;
}

void state_to_local(const LocalPiece& piece, const BondList& global_bonds, const StateArrays& whole, StateArrays& local) {
  for (StateArray& a : local.all()) {
    const StateArray* from = whole.find(a.declaration.name);
    if (!from || !a.declaration.checkpoint) continue;
    if (a.declaration.extent == StateExtent::per_node) a.values = pick_rows(from->values, piece.global, a.declaration.components);
    else a.values = rows_to_local(piece, global_bonds, from->values, piece.model.bonds, a.declaration.components);
  }
}

void rows_to_local(const LocalPiece& piece, const BondList& global, BondList& local) {
  for (std::int32_t l : piece.owned_local) {
    const auto i = static_cast<std::size_t>(piece.global[static_cast<std::size_t>(l)]);
    std::copy(global.broken.begin() + global.offsets[i], global.broken.begin() + global.offsets[i + 1],
              local.broken.begin() + local.offsets[static_cast<std::size_t>(l)]);
  }
}

Vec3Array to_local(const LocalPiece& piece, const Vec3Array& a) {
  Vec3Array out;
  for (int d = 0; d < 3; ++d) out[static_cast<std::size_t>(d)] = pick(a[static_cast<std::size_t>(d)], piece.global);
  return out;
}

}  // namespace pd
