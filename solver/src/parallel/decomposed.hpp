// What the operator asks of a decomposed run (issue 15), without naming MPI: fill the ghosts of a
// per-node array before a sweep, and sum per-node values exactly, so the sum does not depend on the
// decomposition. parallel/mpi_decomposed implements it with MPI; a serial run has none (null), and
// parallel/node_sum.hpp then sums the same terms with the same exact sum.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/bonds.hpp"
#include "core/exact_sum.hpp"
#include "core/nodes.hpp"
#include "parallel/node_columns.hpp"
#include "parallel/row_split.hpp"

namespace pd {

struct LocalPiece;

// The ghosts' exchange over a set of nodes other than the piece's (the contact ghosts of
// forces/contact_on_piece): made by Decomposed::make_node_halo, rebuilt with the set.
class NodeHalo {
 public:
  virtual ~NodeHalo() = default;
  // The ghost entries of a per-node array over the set = their owners' entries. Collective.
  virtual void exchange(Vec3Array& a) const = 0;
};

class Decomposed {
 public:
  virtual ~Decomposed() = default;
  // Sets the ghost entries of local per-node arrays (the displacement; LPS's P_i between its two
  // sweeps; several at once: parallel/node_columns.hpp) to their owners' values: exact copies, so a
  // row sums the same bits as on one rank. Collective.
  void update_ghosts(const NodeColumns& a) const {
    begin_update_ghosts(a);
    end_update_ghosts(a);
  }
  // update_ghosts in two halves, so that the rows that read no ghost are swept while the values
  // travel (parallel/row_split.hpp says why and how): begin sends a's owned entries to the ranks
  // that hold them as ghosts and returns; end (with the same arrays) waits and sets a's ghost
  // entries. Nothing may write a's owned entries or read its ghost entries in between, and one
  // exchange runs at a time.
  virtual void begin_update_ghosts(const NodeColumns& a) const = 0;
  virtual void end_update_ghosts(const NodeColumns& a) const = 0;
  // The piece's owned rows split into those that read no ghost and the others, made once with the
  // piece (its rows never change).
  virtual const RowSplit& row_split() const = 0;
  // begin_update_ghosts(a) and the handle an overlapped sweep waits on (row_split.hpp): its wait()
  // ends this exchange, once. a's arrays must outlive the handle.
  GhostsInFlight send_ghosts(const NodeColumns& a) const {
    begin_update_ghosts(a);
    return GhostsInFlight(row_split(), [this, a] { end_update_ghosts(a); });
  }
  // start + Σ over owned local nodes of per_node[l], summed exactly (core/exact_sum.hpp) and rounded
  // once, the same on every rank: the bits do not depend on the rank or thread count, and equal
  // the serial exact sum (parallel/node_sum.hpp) of the whole model's terms. Entries of ghosts are
  // ignored; a node that no term concerns may enter as 0.0, which adds nothing. Collective: every
  // rank calls it (one MPI_Allreduce of ExactSum::kLimbs int64).
  virtual double exact_sum(const std::vector<double>& per_node, double start = 0.0) const = 0;
  // sums[0 … count) = the sums over all ranks of every rank's sums[0 … count), exactly, and
  // integers[0 … integer_count) the same for integers, in the same one MPI_Allreduce: every
  // reduction a step needs at one point goes in one message, since each collective is a point where
  // every rank waits for the slowest (docs/performance.md, MPI). Collective.
  virtual void reduce(ExactSum* sums, int count, std::int64_t* integers = nullptr, int integer_count = 0) const = 0;
  // Σ over ranks of an integer (exact, so the order does not matter). Collective.
  virtual std::int64_t total(std::int64_t local) const = 0;
  // The least of the ranks' values (exact, so the order does not matter). Collective.
  virtual double minimum(double local) const = 0;

  virtual int rank() const = 0;
  virtual int ranks() const = 0;
  virtual const LocalPiece& piece() const = 0;
  virtual LocalPiece& piece() = 0;
  // The owned entries of a local per-node array, in global node order, on rank 0 (empty elsewhere).
  // Collective.
  virtual std::vector<double> gather(const std::vector<double>& per_node) const = 0;
  Vec3Array gather(const Vec3Array& a) const {
    return {gather(a[0]), gather(a[1]), gather(a[2])};
  }
  // The same for `width` values per node (local node l's at width·l …), in one message per rank:
  // on rank 0 width × (global nodes) values, node g's at width·g … (empty elsewhere). Collective.
  virtual std::vector<double> gather(const std::vector<double>& per_node, int width) const = 0;
  // values = rank 0's values on every rank (the same size everywhere). Collective.
  virtual void broadcast(std::vector<double>& values) const = 0;
  // Every rank's `values` (any length, the ranks' may differ), rank after rank, on every rank
  // (MPI_Allgatherv): a small graph that every rank then judges alike, as mixed's load path joins
  // the ranks' components of the bond graph (integrators/load_path.hpp). Collective.
  virtual std::vector<std::int64_t> gather_to_all(const std::vector<std::int64_t>& values) const = 0;
  // The broken flags of the owned rows into the whole model's bond list, on rank 0 (whose rows the
  // frames' damage reads). Collective.
  virtual void gather_broken(const BondList& local, BondList& global) const = 0;
  // `width` values per directed bond of the owned rows of `local` (a per-bond array of the piece, as
  // a law's declared history) in the whole model's bond order — the rows of `global`, whose offsets
  // rank 0 holds — on rank 0 (empty elsewhere). Collective.
  virtual std::vector<double> gather_bond_values(const BondList& local, const std::vector<double>& per_bond, int width,
                                                 const BondList& global) const = 0;
  // The broken bonds of the owned rows, each once from its lower-numbered end (j > i), as rows of
  // the whole model on rank 0: lines.offsets over every node, lines.neighbour the global j's in row
  // order, lines.broken all 1 (empty elsewhere). What a gathered frame's line cells need, without
  // the whole bond list (issue 15). Collective.
  virtual void gather_broken_lines(const BondList& local, BondList& lines) const = 0;
  // Every rank's (key, value) entries on rank 0, sorted by key (empty elsewhere); a key comes from
  // one rank only. A few values from each rank that rank 0 adds in the serial run's order (the
  // reaction of a support: core/reactions.hpp), without gathering the whole model. Collective.
  virtual std::vector<std::pair<std::int64_t, double>> gather_keyed(const std::vector<std::int64_t>& keys,
                                                                    const std::vector<double>& values) const = 0;
  // Every rank's value, rank after rank, on rank 0 (empty elsewhere): run.log's per-rank lines. Collective.
  virtual std::vector<double> per_rank(double value) const = 0;
  // Rank 0's bytes on every rank (MPI_Bcast): what rank 0 alone read (a checkpoint file, or the
  // error it met reading it) so that every rank decides alike. Collective.
  virtual std::string broadcast(const std::string& bytes_on_rank_0) const = 0;

  // Contact between bodies and fragments on several ranks (forces/contact_on_piece). Each rank
  // gives its box [lo, hi] and its candidate nodes (global numbers, ascending, with their positions
  // and `width` values each); every rank's box goes to all (MPI_Allgather), and each candidate
  // inside another rank's box goes to that rank with its values (MPI_Alltoallv). Out: the nodes
  // received, ascending by global number (a node comes from its one owner, so once), with their
  // values. Collective.
  virtual void exchange_in_boxes(const double lo[3], const double hi[3], const std::vector<std::int32_t>& global_node,
                                 const Vec3Array& position, const std::vector<double>& values, int width,
                                 std::vector<std::int32_t>& received_node, std::vector<double>& received_values) const = 0;
  // A halo over a set of nodes numbered locally in ascending global order (`global`): the entries
  // `ghost_local` come from their owners; every rank's set holds its own owned nodes that others
  // ask for. Collective.
  virtual std::unique_ptr<NodeHalo> make_node_halo(const std::vector<std::int32_t>& global,
                                                   const std::vector<std::int32_t>& ghost_local) const = 0;
  // run.log's lines on the contact ghosts' traffic (box exchanges, their halo), per rank and per
  // step of `steps`, like traffic_report. Collective; the lines on rank 0 (empty elsewhere).
  virtual std::vector<std::string> contact_traffic_report(std::int64_t steps) const = 0;

  // What this rank's communication has cost so far (issue 15's per-step measures): halo exchanges,
  // exact sums and gathers, with their wall time.
  struct Traffic {
    std::int64_t halo_exchanges = 0, halo_messages = 0, halo_bytes = 0;  // sent by this rank
    std::int64_t reductions = 0, reduction_bytes = 0;  // MPI_Allreduce calls (exact sums, totals, minima) and their bytes
    std::int64_t gathers = 0, gather_bytes = 0;        // gathers to rank 0 (frames, history, setup): calls and bytes sent
    // Wall time inside MPI calls and packing (reductions: every Allreduce and the gathers), waits
    // for the other ranks included: a collective returns when the slowest rank has entered it.
    double halo_seconds = 0.0, reduction_seconds = 0.0;
    // Of halo_seconds, the time in the exchanges' second halves: the wait for the messages that the
    // interior rows' sweep did not hide (parallel/row_split.hpp), and the unpacking.
    double halo_wait_seconds = 0.0;
  };
  virtual Traffic traffic() const = 0;
  // run.log's lines on the decomposed run's communication: per rank, per step of `steps`, the
  // messages and bytes it sent, its ghosts per owned node, the time in communication and its peak
  // memory. Collective; the lines on rank 0 (empty elsewhere).
  virtual std::vector<std::string> traffic_report(std::int64_t steps) const = 0;
};

struct Model;
// A run on several MPI ranks: the model decomposed over them (parallel/mpi_decomposed); null for a
// run on one rank (or a build without MPI), which then takes the serial path. Collective.
std::unique_ptr<Decomposed> decompose_over_ranks(const Model& global);
struct CrackSegment;
// The same without the whole bond list (issue 15): `skeleton` is build_model_without_bonds's model
// with every node's row length in bonds.offsets (core/bonds count_bonds) and its law; each rank
// builds only the rows of the nodes it owns (cut-off, pre-cracks) and the surface correction's
// factors of `surface_correction` on them. Its piece is bitwise the one decompose_over_ranks cuts
// from the whole model. Collective.
std::unique_ptr<Decomposed> decompose_rows_over_ranks(const Model& skeleton, double cutoff,
                                                      const std::vector<CrackSegment>& cracks,
                                                      const std::string& surface_correction);

}  // namespace pd
