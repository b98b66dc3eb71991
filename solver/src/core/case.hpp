// The resolved case (pipeline/formats.md §3) as plain values, after io/case_reader checked them.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/material.hpp"

namespace pd {

struct BoundaryCondition {
  std::string set;
  std::string kind;  // displacement | velocity | body_force
  int component = 0;
  std::vector<double> times, values;  // piecewise linear, held constant outside
};

struct InitialCondition {
  std::string set;
  std::string kind;  // velocity | displacement
  int component = 0;
  double value = 0.0;
  double gradient = 0.0;  // displacement only: u = value + gradient·x[component] (a uniform pre-strain)
};

struct TimeSettings {
  double end = 0.0;
  std::string integrator = "verlet";
  std::string dt_rule = "stable";  // "stable", "exact" or "fixed"
  double dt_value = 0.0;           // the number when dt_rule == "fixed"
  double safety_factor = 0.8;
  std::int64_t max_steps = 100000000;
};

// adaptive: the mixed explicit–implicit step of thesis §2.2 (integrators/adaptive.hpp).
struct AdaptiveSettings {
  double tol = 1e-3;  // TOL of eq. 2.7
  int kd = 20;        // K_d, the desired number of fixed-point iterations
  double p = 3.0;     // the exponent p of eq. 2.8
  double phi = 1.0;   // φ: weight of the end-of-step force (1 thesis, ½ trapezoidal)
  std::optional<double> dt_initial, dt_min, dt_max;  // [s]; empty: derived from eq. 2.5
};

// Newton's settings, one block shared by quasi_static and implicit (and so by mixed, which runs
// their load steps and steps): each section reads it with the same table (io/case_settings.cpp).
struct NewtonSettings {
  explicit NewtonSettings(int max_iterations) : max_iterations(max_iterations) {}
  // TOL on ω_K = ‖Δu_K‖/‖u_K − u_n‖ (eq. 2.6 for Newton's corrections); the key is quasi_static.tol
  // and implicit.newton_tol (implicit.tol is the step's error tolerance).
  double newton_tol = 1e-6;
  // Equilibrium: the residual over free components ≤ this × the load's scale (quasi_static: the
  // reactions and body forces; implicit: ‖inertia‖ + ‖force‖).
  double residual_tol = 1e-8;
  int kd = 5;          // K_d: the Newton iterations a step is aimed at (eq. 2.8)
  double p = 2.0;      // exponent of eq. 2.8
  int max_iterations;  // Newton iterations before the step is cut (quasi_static 30, implicit 20)
  // [s]; empty: quasi_static end/100, end·1e-6, end/10; implicit time.dt, 1e-6 × eq. 2.5, end/10.
  std::optional<double> dt_initial, dt_min, dt_max;
  // The linear solve of each Newton iteration (integrators/newton_krylov.hpp): "direct" (CHOLMOD),
  // "cg" (matrix-free preconditioned CG, an inexact Newton–Krylov iteration) or "auto" (cg when the
  // scene has no assembled tangent, contact, or when it is large; direct otherwise).
  std::string linear_solver = "auto";
  int cg_max_iterations = 5000;  // CG iterations per Newton iteration before it takes the iterate it has
};

// quasi_static: time is a load parameter; each load step is solved for equilibrium by Newton
// (integrators/quasi_static.hpp), its size set by eq. 2.8 from the iterations it took.
struct QuasiStaticSettings : NewtonSettings {
  QuasiStaticSettings() : NewtonSettings(30) {}
  int max_breaking_rounds = 100;  // re-solves at one load while bonds keep breaking, then unstable
  // A load step that overshoots the first bond failure is redone to it (integrators/quasi_static.hpp).
  bool cut_to_first_failure = true;
  // CG's preconditioner (integrators/quasi_static.cpp, choose_preconditioner): "block_jacobi" (the
  // node blocks of K, matrix-free), "amg" (hypre's BoomerAMG on the assembled K: linalg/amg.hpp) or
  // "auto" (amg for large 3D models when it fits in memory, block_jacobi otherwise).
  std::string preconditioner = "auto";
};

// implicit: dynamics by the generalized-α method solved by Newton (integrators/implicit.hpp), the
// step set by a local error estimate and by eq. 2.8 from the Newton iterations; its linear solve
// is block-Jacobi CG when cg.
struct ImplicitSettings : NewtonSettings {
  ImplicitSettings() : NewtonSettings(20) {}
  double rho_infinity = 1.0;  // ρ∞: spectral radius at infinite frequency (1: trapezoidal, no dissipation)
  double tol = 1e-3;          // TOL on the local error estimate relative to the step's motion
};

// mixed: quasi-static load steps while the body is in equilibrium, Verlet while a crack runs
// (integrators/mixed.hpp); the quasi_static section sets the load steps, time.dt the explicit ones.
struct MixedSettings {
  std::string start = "quasi_static";  // quasi_static | implicit: the scheme away from a running crack
  int unstable_rounds = 3;         // re-solves at one load while bonds break, then explicit
  double kinetic_fraction = 0.05;  // back to quasi-static once kinetic < this × strain energy ...
  std::int64_t arrest_steps = 200;  // ... for this many explicit steps without a bond breaking
};

struct OutputSettings {
  std::optional<double> every_time;        // s
  std::optional<std::int64_t> every_steps;
  std::int64_t history_every = 1;
  std::vector<std::string> reactions;      // node sets whose reaction force goes to history.csv
  std::vector<std::string> probes;         // node sets whose mean displacement and velocity go to history.csv
  // A checkpoint (io/checkpoint.hpp) after the first step at or past every k·restart_every_time of
  // simulated time and/or every restart_every_steps steps; neither: only on SIGINT/SIGTERM.
  std::optional<double> restart_every_time;  // s
  std::optional<std::int64_t> restart_every_steps;
  // And one every restart_every_wall seconds of wall time (0: none), on by default, so that a run
  // killed without a signal to catch (SIGKILL, a machine going down) loses at most that much
  // (run/schedule.hpp WallCheckpoints).
  double restart_every_wall = 600.0;  // s
  // How frames are stored (pipeline/formats.md §4; checkpoints are always exact): the point fields
  // rounded to float32 or kept float64 (reference points stay Float64 either way), zlib blocks as
  // VTK's vtkZLibDataCompressor writes them or raw, and which point fields a frame carries (the
  // names of io/output.hpp frame_fields()).
  std::string precision = "float32";  // float32 | float64
  std::string compression = "zlib";   // zlib | none
  std::vector<std::string> fields = {"displacement", "velocity", "damage", "block"};
  std::string gmsh = "figures";       // read by postprocess only: all | figures | none
  // A decomposed run's frames (pipeline/formats.md §4): one .vtu piece per rank named by a .pvtu
  // (no rank holds the whole model for them, issue 37), or, when asked, gathered on rank 0 into the
  // serial run's .vtu. A run on one rank writes the gathered (plain) .vtu whatever this says.
  std::string parallel_frames = "pieces";  // pieces | gathered
};

// A pre-crack: bonds crossing the segment from–to (in the xy plane; in 3D the plane through it
// parallel to z) start broken (core/cracks.hpp).
struct CrackSegment {
  std::array<double, 3> from{}, to{};  // [m]
};

// contact: short-range forces between nodes (docs/theory.md T8).
struct ContactSettings {
  std::string enabled = "auto";   // auto | on | off
  bool self_contact = false;      // also between nodes of the same block (fragments)
  double skin = 0.0;              // Verlet-list skin [m]; 0 → half the grid spacing
  double stiffness_factor = 15.0; // c_s = factor·c (Silling's EMU value 15, as LAMMPS)
};

// A rigid indenter (LAMMPS fix indent): force density K·(R − r)² on nodes inside it.
struct IndenterSettings {
  std::string name;
  std::string shape;                 // sphere | cylinder | plane (registry in forces/indenter)
  double radius = 0.0;               // R [m] (sphere, cylinder)
  std::array<double, 3> centre{};    // at t = 0 [m]; a point of the plane
  std::array<double, 3> velocity{};  // [m/s]
  std::array<double, 3> normal{};    // plane: unit normal out of the indenter, towards the body
  std::array<double, 3> axis{};      // cylinder: unit axis (z for a disk in a 2D case)
  double stiffness = 0.0;            // K [N/m⁵]
};

struct Case {
  std::filesystem::path file;  // case.json itself
  std::string name, source, title;
  std::filesystem::path nodes_file, output_dir;  // resolved against the case.json directory
  int dimension = 3;
  std::string analysis = "3d";
  double thickness = 0.0;  // h [m], 2D only
  double grid_spacing = 0.0;
  double horizon = 0.0;
  std::string partial_volume = "none";  // docs/theory.md T5: none | lammps | hhb
  // none | energy | volume (Le & Bobaru 2018, core/surface_correction): energy, per-bond factors
  // from the energy of a uniaxial stress along each axis on each node's family against the
  // continuum's; volume, from the family volumes.
  std::string surface_correction = "none";
  std::vector<BlockMaterial> blocks;
  // thesis: a bond over its critical stretch breaks before the force at the new state (§2.2);
  // lammps: it carries its force in that step and breaks after it (LAMMPS peri/pmb).
  std::string breaking_order = "thesis";
  std::vector<std::string> no_fail_sets, node_sets;
  std::vector<BoundaryCondition> boundary_conditions;
  std::vector<InitialCondition> initial_conditions;
  std::vector<CrackSegment> cracks;
  double damping = 0.0;  // α [1/s]
  ContactSettings contact;
  std::vector<IndenterSettings> indenters;
  TimeSettings time;
  AdaptiveSettings adaptive;
  QuasiStaticSettings quasi_static;
  ImplicitSettings implicit;
  MixedSettings mixed;
  OutputSettings output;
};

}  // namespace pd
