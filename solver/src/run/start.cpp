// The start phase of a run: fresh start or restore, and the checkpoint that restore reads back (run/start.hpp).
#include "run/start.hpp"

#include "core/conditions.hpp"
#include "io/output_lock.hpp"
#include "io/read_file.hpp"
#include "parallel/local_model.hpp"
#include "run/measures.hpp"
#include "run/state_checkpoint.hpp"
#include "run/text.hpp"

namespace pd {

namespace {

// Every refusal of a checkpoint says how to start over instead (the Makefile resumes whenever
// checkpoint.bin is newer than the case, so a refused one would otherwise block every `make`).
Error start_over(const RunOptions& opt, const std::exception& e) {
  // Deleting is the advice for a damaged or foreign checkpoint file, not for a directory or a
  // device given by mistake (io/read_file.cpp says what to give instead).
  if (!std::filesystem::is_regular_file(opt.restart)) return Error(e.what());
  return Error(std::string(e.what()) + "; to start the run over instead, delete " + opt.restart.string());
}

// The checkpoint's index (io/checkpoint.hpp; a few hundred bytes, whatever the model). On a
// decomposed run rank 0 alone reads it and broadcasts its bytes (or the error it met): every rank
// then parses the same bytes and checks them alike, so a bad file is refused by every rank with
// one message, and no rank waits for another that gave up.
Checkpoint read_checkpoint_on_ranks(const RunOptions& opt, const Decomposed* d) {
  if (!d) return parse_checkpoint(read_whole_file(opt.restart, "the checkpoint"), opt.restart.string());
  std::string bytes, failure;
  if (d->rank() == 0) try {
      bytes = read_whole_file(opt.restart, "the checkpoint");
    } catch (const Error& e) {
      failure = e.what();
    }
  failure = d->broadcast(failure);
  if (!failure.empty()) throw Error(failure);
  return parse_checkpoint(d->broadcast(bytes), opt.restart.string());
}

// Broken bonds of the whole model, each once: from the whole list, or from the ranks' rows (each
// bond's two copies are in the rows of its two ends, on one rank or two).
std::int64_t broken_bonds(const Prepared& p) {
  if (p.whole_bonds) return broken_bond_count(p.model);
  std::int64_t flags = 0;
  for (std::uint8_t b : p.decomposed->piece().model.bonds.broken) flags += b;
  return p.decomposed->total(flags) / 2;
}

// The checkpoint's linear solver, before initialize() sizes the scratch for it. Auto's choice
// depends on the rank count (a 2-rank quasi_static run solves by CG, one rank would factorise), and
// either gives other bits: kept where this run can (CG runs on any rank count), else said, since
// the restarted run will then not be bitwise the uninterrupted one (issue 36, item 9).
void keep_linear_solver(const RunOptions& opt, Integrator& integrator, const std::string& recorded, Start& s) {
  const std::string here = integrator.linear_solver();
  const std::string why = integrator.keep_linear_solver(recorded);
  if (why.empty()) return;
  s.solver_changed = "pdsolve: warning: " + opt.restart.string() + " was written by a run solving with " + recorded +
                     ", which this run cannot take (" + why + "): it goes on with " + here +
                     ", and its results will not be bitwise those of the uninterrupted run";
}

// Whether the index's arrays are what this run writes: the state, the law's declared state, the
// integrator's per-node arrays and (if the index has it) contact's u_build.
bool fits_sections(const Checkpoint& index, const Model& local, Integrator& integrator, bool& contact) {
  contact = false;
  for (const CheckpointSection& section : index.sections) contact = contact || section.name == "contact_u_build.x";
  return index.sections == checkpoint_sections_of(local, integrator.checkpointed_node_arrays().size(), contact);
}

// Replaces the fresh state by the checkpoint's, after checking that it belongs to this case: the
// index on every rank, then each rank streams the pieces and keeps its own nodes and rows
// (run/state_checkpoint.hpp), whatever rank count wrote them.
void restore(const RunOptions& opt, Prepared& p, Start& s) {
  Model& model = p.model;
  Integrator& integrator = *p.integrator;
  Decomposed* dec = p.decomposed.get();
  LocalPiece* piece = dec ? &dec->piece() : nullptr;
  Model& local = piece ? piece->model : model;  // the operator's model
  const auto n = static_cast<std::size_t>(p.nodes);
  Checkpoint checkpoint = read_checkpoint_on_ranks(opt, dec);
  const std::string where = opt.restart.string() + ": ";
  if (checkpoint.case_hash != s.case_hash)
    throw Error(where + "the checkpoint belongs to another case file (or " + opt.case_file.string() +
                " changed since it was written); restart with the case.json it was written for");
  if (checkpoint.nodes_hash != s.nodes_hash)
    throw Error(where + "the checkpoint belongs to another node file (or " + p.c.nodes_file.string() +
                " changed since it was written)");
  const auto directed = static_cast<std::size_t>(p.directed_bonds());
  bool contact = false;
  if (checkpoint.nodes != n || checkpoint.directed_bonds != directed || !fits_sections(checkpoint, local, integrator, contact) ||
      checkpoint.integrator != integrator.name() || (contact && !model.contact.pairs))
    throw Error(where + "the checkpoint does not fit this model (" + std::to_string(checkpoint.nodes) + " nodes, " +
                std::to_string(checkpoint.directed_bonds / 2) + " bonds, integrator " + checkpoint.integrator + "; here " +
                std::to_string(n) + ", " + std::to_string(directed / 2) + ", " + integrator.name() + ")");
  if (checkpoint.frame_times.empty()) throw Error(where + "the checkpoint lists no frame; cannot restart");
  keep_linear_solver(opt, integrator, checkpoint.linear_solver, s);
  // The series goes on in the format it was written in, whatever the rank count and output.parallel_frames.
  p.resumes_pieces = checkpoint.frames_in_pieces;
  p.c.output.parallel_frames = checkpoint.frames_in_pieces ? "pieces" : "gathered";
  // initialize() sizes the integrator's scratch; then everything it set is replaced by the
  // checkpoint, so the run continues bitwise as if it had never stopped.
  s.state = State(local.nodes.size());
  integrator.initialize(s.state, checkpoint.loop.t);
  s.state.copy_totals(checkpoint.state);
  Vec3Array u_build;
  restore_from_pieces(opt.restart, checkpoint, local, piece, s.state, integrator.checkpointed_node_arrays(),
                      contact ? &u_build : nullptr, dec && p.whole_bonds ? &model.bonds : nullptr);
  // Every rank decides alike: one rank's non-finite entry stops them all.
  bool finite = first_non_finite(s.state) < 0;
  if (dec) finite = dec->minimum(finite ? 1.0 : 0.0) == 1.0;
  if (!finite) throw Error(where + "the checkpoint's state is not finite");
  if (model.contact.pairs && dec) {
    // The piece's record of the last build; its first force evaluation searches again at that
    // displacement on every rank (forces/contact_on_piece), the list the serial restore finds.
    local.contact_list.restore_record(u_build, checkpoint.contact_rebuilds, checkpoint.contact_seconds);
  } else if (model.contact.pairs)
    model.contact_list.restore(model.nodes.x, u_build, model.block_index, model.contact, checkpoint.contact_rebuilds,
                               checkpoint.contact_seconds);
  try {
    integrator.load_state(checkpoint.integrator_state);
  } catch (const std::exception& e) {
    throw Error(where + e.what());
  }
  s.loop = checkpoint.loop;
  s.resume = OutputResume{std::move(checkpoint.frame_times), checkpoint.history_bytes};
}

}  // namespace

Start start_or_restore(const RunOptions& opt, Prepared& p) {
  Start s;
  // A decomposed run's state is its piece's (owned nodes and ghosts): the whole cloud's state is
  // never made on a rank, 80 bytes a node (issue 15). A restart sizes it in restore().
  if (!p.decomposed) s.state = State(p.model.nodes.size());
  s.restarting = !opt.restart.empty();
  s.case_hash = file_hash(opt.case_file);
  s.nodes_hash = file_hash(p.c.nodes_file);
  if (s.restarting) {
    try {
      restore(opt, p, s);
    } catch (const Error& e) {
      throw start_over(opt, e);
    }
  } else {
    // On a decomposed run, on the piece's nodes (owned and ghosts): a node's initial value depends
    // only on its own position and set membership, which the piece holds as copies, so each entry
    // is the whole cloud's, bit for bit. The operator works on the piece.
    if (p.decomposed) {
      const LocalPiece& piece = p.decomposed->piece();
      s.state = State(piece.size());
      apply_initial_conditions(p.c, piece.model.nodes, s.state.u, s.state.v);
    } else {
      apply_initial_conditions(p.c, p.model.nodes, s.state.u, s.state.v);
    }
    p.integrator->initialize(s.state, 0.0);
    s.loop.dt = p.dt;
    s.loop.broken = broken_bonds(p);
  }
  release_whole_rows_offsets(p);  // a restart's flags were taken by the rows of the whole list
  if (first_non_finite(s.state) >= 0)
    throw Error((s.restarting ? opt.restart.string() + ": the checkpoint's state" : p.c.file.string() + ": the initial state") +
                " is not finite");
  return s;
}

std::filesystem::path checkpoint_path(const Case& c) { return (c.output_dir / "checkpoint.bin").lexically_normal(); }

std::unique_ptr<OutputWriter> open_output(const RunOptions& opt, const Prepared& p, const Start& s,
                                          const HistoryColumns& columns) {
  if (!p.writes_output()) return nullptr;
  // The folder's lock before any file in it changes: make, peridyn and a pdsolve started by hand
  // never write into one folder at once (io/output_lock.hpp).
  auto lock = std::make_unique<OutputLock>(p.c.output_dir, "pdsolve " + opt.case_file.string());
  // The frames' format (output.precision, compression, fields) reaches the writer here.
  FrameFormat format = frame_format_of(p.c.output);
  format.pieces = p.frames_in_pieces();
  std::unique_ptr<OutputWriter> out;
  if (!s.restarting) {
    out = std::make_unique<OutputWriter>(p.c.output_dir, columns.names(), nullptr, format);
  } else {
    try {
      out = std::make_unique<OutputWriter>(p.c.output_dir, columns.names(), &s.resume, format);
    } catch (const Error& e) {  // history.csv shorter than recorded, a frame missing
      throw start_over(opt, e);
    }
  }
  out->hold(std::move(lock));
  return out;
}

Checkpoint checkpoint_of(const Prepared& p, const Start& s, const State& totals, const LoopState& loop,
                         const OutputWriter& out, std::vector<char> integrator_state, bool contact,
                         std::vector<CheckpointPieceRef> pieces) {
  const Model& model = p.model;
  Checkpoint k;
  k.case_hash = s.case_hash;
  k.nodes_hash = s.nodes_hash;
  k.nodes = model.nodes.size();
  k.directed_bonds = static_cast<std::size_t>(p.directed_bonds());
  k.integrator = p.integrator->name();
  k.linear_solver = p.integrator->linear_solver();
  k.frames_in_pieces = p.frames_in_pieces();
  k.loop = loop;
  k.integrator_state = std::move(integrator_state);
  k.state.copy_totals(totals);
  // The operator's model: the piece's on a decomposed run; its declared arrays are every rank's.
  const Model& local = p.op->model();
  k.sections = checkpoint_sections_of(local, p.integrator->checkpointed_node_arrays().size(), contact);
  k.pieces = std::move(pieces);
  k.contact_rebuilds = local.contact_list.rebuilds();
  k.contact_seconds = local.contact_list.seconds();
  k.frame_times = out.frame_times();
  k.history_bytes = out.history_bytes();
  return k;
}

}  // namespace pd
