"""The case-file schema, declared once: every key with its type, default, SI unit and one-line doc.

Each stage reads the part it needs from the validated case; docs/case-file.md is
generated from this table (`/usr/bin/python3 -m pipeline.schema`), so the
documentation cannot drift from what the code accepts.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

REQUIRED = object()  # marks a key without a default


@dataclass
class Key:
    """One key of the case file.

    kind: number | integer | string | choice | section | named (user-named
    sub-sections, e.g. materials) | list (of sections) | names (list of strings) | boolean
    | components (x/y/z → number or [[t, v], ...] table) | numbers (list of
    numbers) | parameters (name → number) | number_or_choice | point_or_name (a point
    [x, y] or [x, y, z], or a node-set name).
    """
    kind: str
    doc: str
    default: Any = None
    unit: str = ""
    choices: tuple = ()
    minimum: float | None = None          # inclusive
    above: float | None = None            # exclusive lower bound
    maximum: float | None = None          # inclusive
    below: float | None = None            # exclusive upper bound
    fields: dict[str, "Key"] = field(default_factory=dict)
    table: bool = True                    # components: allow a time table

    @property
    def required(self) -> bool:
        return self.default is REQUIRED


def section(doc: str, **fields: Key) -> Key:
    return Key("section", doc, default={}, fields=fields)


COMPONENT_DOC = ("per component x, y, z: a number, or a table [[t0, v0], [t1, v1], ...] "
                 "interpolated linearly in time and held constant outside it")

MATERIAL = {
    "model": Key("choice", "constitutive model: pmb (bond-based prototype microelastic brittle; fixes ν) or "
                 "lps (linear peridynamic solid, ordinary state-based; any ν)",
                 default="pmb", choices=("pmb", "lps")),
    "density": Key("number", "mass density ρ", default=REQUIRED, unit="kg/m³", above=0.0),
    "youngs_modulus": Key("number", "Young's modulus E (bond-based PMB fixes ν: 1/4 in 3D and "
                          "plane strain, 1/3 in plane stress); give it, or (pmb) micromodulus", default=None,
                          unit="Pa", above=0.0),
    "poisson_ratio": Key("number", "Poisson's ratio ν of the isotropic solid; lps only, required there "
                         "(−1 < ν < 1/2: K and G positive)", default=None, above=-1.0, below=0.5),
    "fracture_energy": Key("number", "critical energy release rate G0, with youngs_modulus; omit for an "
                           "unbreakable material", default=None, unit="J/m²", above=0.0),
    "influence": Key("choice", "lps only: influence function ω(|ξ|), one, inverse_length (1/|ξ|) or gaussian "
                     "(exp(−|ξ|²/δ²)); default one, the same in every block", default=None,
                     choices=("one", "inverse_length", "gaussian")),
    "micromodulus": Key("number", "pmb only: the micromodulus c itself, instead of youngs_modulus (LAMMPS "
                        "pair_coeff's c; docs/lammps.md)", default=None, unit="N/m⁶", above=0.0),
    "critical_stretch": Key("number", "pmb only: the critical stretch s0 itself, with micromodulus (LAMMPS "
                            "pair_coeff's s00); omit for an unbreakable material", default=None,
                            above=0.0),
    "critical_stretch_alpha": Key("number", "pmb only: α of LAMMPS's rule s0_i = s0 − α·min_j s_ij (per node, "
                                  "from the previous step's stretches; a bond breaks when s > min(s0_i, s0_j)); "
                                  "omitted: 0, s0 stays fixed", default=None, minimum=0.0),
}

# The material keys each model reads (besides model and density), and what a key means to a model
# that has no such parameter: validate.py rejects such a key with this explanation, as the solver's
# reader does (solver/src/io/case_reader.cpp read_block).
MODEL_KEYS = {
    "pmb": ("youngs_modulus", "fracture_energy", "micromodulus", "critical_stretch", "critical_stretch_alpha"),
    "lps": ("youngs_modulus", "poisson_ratio", "fracture_energy", "influence"),
}
# PMB needs youngs_modulus or micromodulus (validate.py _check_pmb_pairs).
MODEL_REQUIRED = {"lps": ("youngs_modulus", "poisson_ratio")}
MODEL_NOTE = {
    "pmb": "PMB is bond-based and fixes Poisson's ratio (1/4 in 3D and plane strain, 1/3 in plane stress)",
}

BOUNDARY_CONDITION = {
    "set": Key("string", "node set (a gmsh physical group name)", default=REQUIRED),
    "displacement": Key("components", "prescribed displacement; " + COMPONENT_DOC, unit="m"),
    "velocity": Key("components", "prescribed velocity; " + COMPONENT_DOC, unit="m/s"),
    "body_force": Key("components", "body force density b added to every node of the set "
                      "(thesis §2.1: loads act in a layer); " + COMPONENT_DOC, unit="N/m³"),
}

INITIAL_CONDITION = {
    "set": Key("string", "node set (a gmsh physical group name)", default=REQUIRED),
    "velocity": Key("components", "initial velocity per component x, y, z", unit="m/s", table=False),
    "displacement": Key("components", "initial displacement per component x, y, z", unit="m",
                        table=False),
    "strain": Key("components", "uniform initial strain per component x, y, z: adds the affine "
                  "displacement u_x = strain_x·x (y, z alike) to displacement (a pre-strain; hold it "
                  "with a velocity 0 boundary condition)", table=False),
}

INDENTER = {
    "name": Key("string", "name of the indenter (history.csv columns indenter_<name>_fx, _fy, _fz)",
                default=REQUIRED),
    "shape": Key("choice", "sphere, cylinder (a disk in 2D) or plane", default=REQUIRED,
                 choices=("sphere", "cylinder", "plane")),
    "radius": Key("number", "radius R (sphere, cylinder)", default=None, unit="m", above=0.0),
    "centre": Key("numbers", "centre (sphere, cylinder) or a point of the plane at t = 0, [x, y(, z)]",
                  default=REQUIRED, unit="m"),
    "velocity": Key("numbers", "constant velocity of the indenter, [vx, vy(, vz)]", default=None, unit="m/s"),
    "normal": Key("numbers", "plane: normal pointing out of the indenter, towards the body it pushes",
                  default=None),
    "axis": Key("numbers", "cylinder: axis direction (default z: a disk in a 2D case)", default=None),
    "stiffness": Key("number", "K of the force density K·h² (LAMMPS fix indent; a force density "
                     "as in LAMMPS PERI). Its stiffness 2K·h at depth h joins the stable step, so a "
                     "Verlet run's log says how deep the indenter may push a node with the step "
                     "still guaranteed stable, and warns once (step, node, depth) if a node gets "
                     "deeper", default=REQUIRED, unit="N/m⁵", above=0.0),
}

CRACK = {
    "from": Key("numbers", "one end of the crack segment, [x, y(, z)]", default=REQUIRED, unit="m"),
    "to": Key("numbers", "the other end, [x, y(, z)]", default=REQUIRED, unit="m"),
}

CASE = {
    "title": Key("string", "a one-line description, shown in figures", default=""),
    "dimension": Key("choice", "spatial dimension of the geometry", default=REQUIRED, choices=(2, 3)),
    "analysis": Key("choice", "3d, or the 2D model; default 3d in 3D and plane_stress in 2D",
                    default=None, choices=("3d", "plane_stress", "plane_strain")),
    "thickness": Key("number", "plate thickness h of a 2D case (node volume = area × h)",
                     default=None, unit="m", above=0.0),
    "geometry": section(
        "how gmsh meshes cases/<case>/<case>.geo",
        parameters=Key("parameters", "values passed to gmsh as -setnumber NAME VALUE, overriding "
                       "the .geo's DefineConstant[] entries", default={}),
    ),
    "discretization": section(
        "how the mesh becomes a node cloud",
        method=Key("choice", "lattice: a regular grid of spacing dx clipped to the mesh (most stable); "
                   "mesh-nodes: the mesh's own nodes", default="lattice",
                   choices=("lattice", "mesh-nodes")),
        dx=Key("number", "lattice spacing; required for lattice", default=None, unit="m", above=0.0),
        horizon_factor=Key("number", "horizon δ = horizon_factor × dx (thesis §2.1: δ = 3dx works well; "
                           "the extra 0.015 keeps lattice bonds at exactly 3dx)", default=3.015, above=0.0),
        horizon=Key("number", "horizon δ; overrides horizon_factor", default=None, unit="m", above=0.0),
        origin=Key("numbers", "lattice: a point [x, y(, z)] the lattice passes through, nodes at "
                   "origin + k·dx (as LAMMPS's lattice puts atoms at k·a); default: cell centres of the "
                   "mesh's bounding box", default=None, unit="m"),
        partial_volume=Key("choice", "share ν of a neighbour's volume inside the horizon (docs/theory.md T5): "
                           "none (full volumes), lammps (ν = (δ − |ξ|)/dx + ½ for δ − dx/2 ≤ |ξ| ≤ δ), "
                           "hhb (family |ξ| − dx/2 ≤ δ, ν = (δ − |ξ| + dx/2)/dx on the outer shell)",
                           default="none", choices=("none", "lammps", "hhb")),
        surface_correction=Key("choice", "surface correction (Le & Bobaru 2018): none; energy (per-bond "
                               "factors from each node's strain energy under a uniaxial stress along each "
                               "axis against the continuum's, combined over the two ends and the bond's "
                               "direction, refined in 3 passes with the factors applied; any node cloud); or volume (g = 2V0/(V_i + V_j), "
                               "V_i a node's family volume, V0 the continuum's)",
                               default="none", choices=("none", "energy", "volume")),
    ),
    "materials": Key("named", "one entry per block, named after a gmsh physical group of the "
                     "top dimension (surface in 2D, volume in 3D)", default=REQUIRED, fields=MATERIAL),
    "node_sets": Key("named", "options of node sets (every gmsh physical group is a node set)",
                     default={}, fields={
                         "layer": Key("number", "nodes within this distance of a curve/surface group "
                                      "belong to it (thesis §2.1: conditions act in a layer), measured "
                                      "through the body (not across a notch or a hole) and to the group's "
                                      "end points too (a round cap there); default: the first row of nodes",
                                      default=None, unit="m", minimum=0.0),
                     }),
    "no_fail": Key("names", "node sets whose bonds never break (e.g. where loads are applied)",
                   default=[]),
    "boundary_conditions": Key("list", "conditions applied during the run", default=[],
                               fields=BOUNDARY_CONDITION),
    "initial_conditions": Key("list", "state at t = 0 (the rest of the body starts at rest)",
                              default=[], fields=INITIAL_CONDITION),
    "cracks": Key("list", "pre-cracks (notches): every bond whose reference segment crosses the segment "
                  "from–to in the xy plane (in 3D: the plane through it parallel to z) starts broken; "
                  "lay it between two rows of nodes", default=[], fields=CRACK),
    "breaking_order": Key("choice", "when a bond over its critical stretch stops carrying force: thesis "
                          "(it breaks before the force at the new state, §2.2) or lammps (it still carries "
                          "its force in the step it breaks and is gone from the next, as LAMMPS peri/pmb; "
                          "docs/lammps.md)", default="thesis", choices=("thesis", "lammps")),
    "damping": Key("number", "velocity damping α: force density −ρ·α·v (the thesis's damping "
                   "correction); 0 for none", default=0.0, unit="1/s", minimum=0.0),
    "contact": section(
        "short-range repulsion between nodes closer than d = min(0.9|ξ|, 1.35dx) (bonded pairs) or "
        "1.35dx (others), force (c_s/δ)(d − r)V_j (thesis §1.1.3; docs/theory.md T8)",
        enabled=Key("choice", "auto: on when the case has more than one block (or self_contact); on; off",
                    default="auto", choices=("auto", "on", "off")),
        self_contact=Key("boolean", "also between nodes of the same block (fragments hitting each other)",
                         default=False),
        skin=Key("number", "Verlet-list skin: the list is rebuilt when a node has moved more than skin/2 "
                 "(default: dx/2)", default=None, unit="m", above=0.0),
        stiffness_factor=Key("number", "contact stiffness c_s = stiffness_factor × c (Silling: 15)",
                             default=15.0, above=0.0),
    ),
    "indenters": Key("list", "rigid indenters moving at a constant velocity, pushing nodes inside them "
                     "with force density K·h², h the depth below the surface (LAMMPS fix indent)",
                     default=[], fields=INDENTER),
    "time": section(
        "time integration",
        end=Key("number", "simulated end time", default=REQUIRED, unit="s", above=0.0),
        integrator=Key("choice", "time integrator: verlet (velocity Verlet, thesis eq. 2.4), adaptive "
                       "(the mixed explicit–implicit step of thesis §2.2, settings in adaptive:) or "
                       "quasi_static (time is a load parameter: equilibrium by Newton at every load step, "
                       "settings in quasi_static:) or mixed (quasi-static load steps while the body is in "
                       "equilibrium, Verlet at time.dt while a crack runs, switching both ways by itself; "
                       "settings in mixed: and quasi_static:) or implicit (dynamics by the generalized-α method "
                       "solved by Newton, the step set by a local error estimate: settings in implicit:)",
                       default="verlet", choices=("verlet", "adaptive", "quasi_static", "mixed", "implicit")),
        dt=Key("number_or_choice", "time step: 'stable' (thesis eq. 2.5, minimised over nodes, times "
               "safety_factor), 'exact' (2/ω_max, ω_max² the largest eigenvalue of the linearised PMB "
               "operator M⁻¹K, times safety_factor: about 1.7× 'stable' in 2D, 2× in 3D), or a number; "
               "for adaptive, the initial step unless adaptive.dt_initial is set",
               default="stable", unit="s", choices=("stable", "exact"), above=0.0),
        safety_factor=Key("number", "fraction of the stable time step used", default=0.8, above=0.0),
        max_steps=Key("integer", "stop after this many steps", default=100_000_000, minimum=1),
    ),
    "adaptive": section(
        "the adaptive step of thesis §2.2 (time.integrator: adaptive): fixed-point iterations with "
        "error ω_K (eq. 2.6) and step factor Φ_K (eq. 2.8)",
        tol=Key("number", "TOL of eq. 2.7: a step is accepted once the last correction is this fraction "
                "of the step's motion", default=1e-3, above=0.0, below=1.0),
        kd=Key("integer", "K_d: the iterations the step size is aimed at; a step not converged after "
               "K_d iterations is redone with a smaller Δt", default=20, minimum=1, maximum=1000),
        p=Key("number", "exponent p of eq. 2.8 (the correction shrinks like Δt^p per iteration; "
              "2 for the linear problem, thesis 3)", default=3.0, above=0.0),
        phi=Key("number", "φ: weight of the end-of-step force and velocity; 1 the thesis form "
                "(first order, dissipative), 0.5 the trapezoidal rule (second order)", default=1.0,
                minimum=0.5, maximum=1.0),
        dt_initial=Key("number", "the first step (default: from time.dt)", default=None, unit="s",
                       above=0.0),
        dt_min=Key("number", "smallest step; not converging there stops the run (default: 1e-6 × "
                   "eq. 2.5)", default=None, unit="s", above=0.0),
        dt_max=Key("number", "largest step (default: the smaller of eq. 2.5 and 0.9 × Δt_exact/(2φ), "
                   "where the fixed-point iteration still contracts)", default=None,
                   unit="s", above=0.0),
    ),
    "quasi_static": section(
        "the quasi-static solver (time.integrator: quasi_static): each load step is brought to "
        "equilibrium by Newton's method with a sparse Cholesky factorisation of the tangent "
        "(CHOLMOD) or matrix-free preconditioned CG (linear_solver), bonds over their critical stretch break and the load step is solved again until "
        "none does; the step size follows eq. 2.8 from the Newton corrections",
        tol=Key("number", "TOL on the last Newton correction relative to the step's motion "
                "(eq. 2.6 for Newton)", default=1e-6, above=0.0, below=1.0),
        residual_tol=Key("number", "equilibrium: the out-of-balance force over free components, "
                         "relative to the load (reactions and body forces)", default=1e-8, above=0.0,
                         below=1.0),
        kd=Key("integer", "K_d: the Newton iterations a load step is aimed at (eq. 2.8)", default=5,
               minimum=1, maximum=1000),
        p=Key("number", "exponent p of eq. 2.8", default=2.0, above=0.0),
        max_iterations=Key("integer", "Newton iterations before the load step is cut", default=30,
                           minimum=1, maximum=100000),
        max_breaking_rounds=Key("integer", "re-solves at one load while bonds keep breaking; more "
                                "means unstable crack growth, and the run stops", default=100,
                                minimum=1, maximum=100000000),
        cut_to_first_failure=Key("boolean", "a load step that ends with bonds over their critical "
                                 "stretch, from a start with none, is redone to the load at which the "
                                 "largest stretch ratio reaches 1 (linear between the two), so that "
                                 "the first bonds break at their load and not all at once past it",
                                 default=True),
        linear_solver=Key("choice", "the linear solve of each Newton iteration: direct (CHOLMOD "
                          "factorisation of the assembled tangent), cg (matrix-free conjugate "
                          "gradients with a block-Jacobi preconditioner, solved only as far as "
                          "Newton needs: Eisenstat–Walker), or auto (cg when a term or the "
                          "material has no assembled tangent, i.e. contact or model lps, or the "
                          "model is large, or the run is on several MPI ranks: run.log says which and "
                          "why); lps cannot use direct, nor a run on several MPI ranks", default="auto", choices=("auto", "direct", "cg")),
        preconditioner=Key("choice", "the preconditioner of CG (linear_solver cg): block_jacobi "
                           "(the 3×3 node blocks of the tangent, matrix-free), amg (algebraic "
                           "multigrid: one V-cycle of hypre's BoomerAMG on the assembled tangent, "
                           "set up again after bonds break or when CG's iterations grow), or auto "
                           "(amg for 3D models with at least 20 000 free dofs whose tangent can be "
                           "assembled, when pdsolve has hypre and its estimated memory fits; "
                           "block_jacobi otherwise, and on several MPI ranks, where amg is refused: run.log says which and why)",
                           default="auto", choices=("auto", "block_jacobi", "amg")),
        cg_max_iterations=Key("integer", "CG iterations in one Newton iteration; then Newton goes "
                              "on with the iterate reached", default=5000, minimum=1,
                              maximum=100000000),
        dt_initial=Key("number", "the first load step (default: end/100)", default=None, unit="s",
                       above=0.0),
        dt_min=Key("number", "smallest load step (default: 1e-6 × end: some ten halvings below "
                   "end/100)", default=None, unit="s",
                   above=0.0),
        dt_max=Key("number", "largest load step (default: end/10)", default=None, unit="s", above=0.0),
    ),
    "implicit": section(
        "implicit dynamics (time.integrator: implicit): the generalized-α method (Chung & Hulbert "
        "1993) solved by Newton's method with a sparse Cholesky factorisation of the tangent plus the "
        "lumped mass (CHOLMOD); the step is limited by accuracy, not by the explicit limit: a local "
        "error estimate (Zienkiewicz & Xie 1991) below tol, and eq. 2.8 from the Newton iterations; "
        "bonds break after each accepted step; damping is integrated implicitly",
        rho_infinity=Key("number", "ρ∞: the amplification of the highest frequencies per step; 1 is "
                         "Newmark's average acceleration (trapezoidal) rule, which conserves the energy "
                         "of a linear system; below 1 damps the high frequencies (0.8: mildly, 0: "
                         "strongest), the low ones barely", default=1.0, minimum=0.0, maximum=1.0),
        tol=Key("number", "TOL on the local error estimate of a step relative to its motion (about the "
                "relative phase error it adds); a step above it is redone with a smaller Δt",
                default=1e-3, above=0.0, below=1.0),
        newton_tol=Key("number", "Newton: the last correction relative to the step's motion (eq. 2.6 "
                       "for Newton); well below tol, so that the iteration error stays under the time error",
                       default=1e-6, above=0.0, below=1.0),
        residual_tol=Key("number", "Newton: the out-of-balance force relative to the inertia plus the "
                         "force", default=1e-8, above=0.0, below=1.0),
        kd=Key("integer", "K_d: the Newton iterations a step is aimed at (eq. 2.8)", default=5,
               minimum=1, maximum=1000),
        p=Key("number", "exponent p of eq. 2.8", default=2.0, above=0.0),
        max_iterations=Key("integer", "Newton iterations before the step is halved", default=20,
                           minimum=1, maximum=100000),
        dt_initial=Key("number", "the first step (default: from time.dt)", default=None, unit="s",
                       above=0.0),
        dt_min=Key("number", "smallest step; a step not accepted there stops the run (default: 1e-6 × "
                   "eq. 2.5)", default=None, unit="s", above=0.0),
        dt_max=Key("number", "largest step (default: end/10)", default=None, unit="s", above=0.0),
        linear_solver=Key("choice", "the linear solve of each Newton iteration, on the tangent plus "
                          "the mass term: direct (CHOLMOD factorisation of the assembled matrix), cg "
                          "(matrix-free conjugate gradients with a block-Jacobi preconditioner), or "
                          "auto (cg for the lps model, for contact, for 3D models with at least 20 000 "
                          "free dofs and on several MPI ranks; direct otherwise: run.log says which and "
                          "why); direct is refused for lps and contact and on several MPI ranks",
                          default="auto", choices=("auto", "direct", "cg")),
        cg_max_iterations=Key("integer", "CG iterations in one Newton iteration; then Newton goes "
                              "on with the iterate reached", default=5000, minimum=1,
                              maximum=100000000),
    ),
    "mixed": section(
        "the mixed scheme (time.integrator: mixed): quasi-static load steps (the quasi_static "
        "section), or implicit generalized-α steps (the implicit section; start: implicit), while the "
        "body is in equilibrium or moves slowly, explicit Verlet steps of time.dt while it is not; "
        "time is physical, so the boundary conditions are loading rates; history.csv's mode column is "
        "1 for a quasi-static step, 2 for an implicit one, 0 for an explicit one, and run.log says "
        "every switch",
        start=Key("choice", "the scheme the run starts with and returns to once a crack has arrested: "
                  "quasi_static (equilibrium load steps, the kinetic energy given up on return) or "
                  "implicit (generalized-α dynamics, the motion kept; no damping needed); implicit "
                  "leaves for explicit when a step fails down to implicit.dt_min or when bonds break "
                  "in more than unstable_rounds implicit steps in a row", default="quasi_static", choices=("quasi_static", "implicit")),
        unstable_rounds=Key("integer", "to explicit when a load step needs more re-solves than this "
                            "while bonds keep breaking (unstable crack growth), or does not converge "
                            "down to quasi_static.dt_min (default there: 10 explicit steps); with "
                            "start: implicit, when bonds break in more than this many implicit steps "
                            "in a row",
                            default=3, minimum=1, maximum=100000000),
        kinetic_fraction=Key("number", "back to the start scheme when the kinetic energy has stayed below "
                             "this fraction of the strain energy ...", default=0.05, above=0.0,
                             below=1.0),
        arrest_steps=Key("integer", "... for this many explicit steps in a row without a bond breaking "
                         "(the crack arrested); back to quasi_static, the kinetic energy left and the strain energy "
                         "above the equilibrium's are given up, as damping work (implicit keeps them). Once the "
                         "cracks have cut the load path between the prescribed motions, quasi_static returns "
                         "δ/c explicit steps after the cut (a stress wave's crossing time of the horizon), or this "
                         "many if fewer or if a block has no youngs_modulus",
                         default=200, minimum=1, maximum=1000000000),
    ),
    "output": section(
        "what the solver writes and how often",
        every_time=Key("number", "a frame every this much simulated time (default: end/50); at most "
                       "10 000 frames (every_steps: the work plan stops more unless FORCE=1)",
                       default=None, unit="s", above=0.0),
        every_steps=Key("integer", "a frame every this many steps (instead of every_time)",
                        default=None, minimum=1),
        history_every=Key("integer", "a history.csv row every this many steps", default=1, minimum=1),
        reactions=Key("names", "node sets whose reaction force (the force the prescribed displacement or "
                      "velocity applies to the set) goes to history.csv as reaction_<set>_fx, _fy, _fz",
                      default=[], unit="N"),
        probes=Key("names", "node sets whose volume-weighted mean displacement and velocity go to history.csv "
                   "at every history row as probe_<set>_ux, _uy, _uz (m) and _vx, _vy, _vz (m/s); figures.probe "
                   "naming one of them draws probe.png from these rows instead of the frames",
                   default=[]),
        restart_every_time=Key("number", "write the checkpoint out/<case>/checkpoint.bin after the first step "
                               "at or past every multiple of this much simulated time (it never shortens a "
                               "step); SIGINT/SIGTERM always write one; `pdsolve case.json --restart "
                               "checkpoint.bin` continues bitwise (pipeline/formats.md §5)",
                               default=None, unit="s", above=0.0),
        restart_every_steps=Key("integer", "write the checkpoint every this many steps (may be combined "
                                "with restart_every_time)", default=None, minimum=1),
        restart_every_wall=Key("number", "write the checkpoint also every this many seconds of wall time "
                               "(0: never), so that a run killed without warning (kill -9, a machine going "
                               "down) loses at most that much; a slow checkpoint pushes the next one back so "
                               "that they take about 3 % of the run at most; the frames and history.csv are the "
                               "same bits with or without",
                               default=600.0, unit="s", minimum=0.0),
        precision=Key("choice", "frames' point fields (displacement, velocity, damage) as float32 or float64; "
                      "reference points, TIME and step stay float64, history.csv and checkpoints are exact "
                      "either way", default="float32", choices=("float32", "float64")),
        compression=Key("choice", "frames' data in zlib blocks as VTK's vtkZLibDataCompressor writes them "
                        "(ParaView, VisIt, meshio read them), or raw", default="zlib", choices=("zlib", "none")),
        fields=Key("names", "point fields a frame carries (postprocess's maps need displacement and damage)",
                   default=["displacement", "velocity", "damage", "block"],
                   choices=("displacement", "velocity", "damage", "block")),
        parallel_frames=Key("choice", "frames of a run on several MPI ranks: pieces (each rank writes its "
                            "nodes to frame_NNNNNN_pR.vtu, rank 0 a frame_NNNNNN.pvtu naming them, so that "
                            "no rank holds the whole model; ParaView and postprocess read them: "
                            "pipeline/formats.md §4) or gathered (rank 0 writes the serial run's "
                            "frame_NNNNNN.vtu; pdsolve --parallel-frames overrides it); one rank always "
                            "writes the plain .vtu",
                            default="pieces", choices=("gathered", "pieces")),
        gmsh=Key("choice", "frames copied into gmsh/results.msh by postprocess: all, only those of the "
                 "figures (figures.times), or none (no gmsh/ files)", default="figures",
                 choices=("all", "figures", "none")),
    ),
    "figures": section(
        "what postprocess draws",
        times=Key("numbers", "simulated times of the damage and displacement maps (default: where bonds "
                  "break, the frames at 10, 50 and 90 % of the final broken-bond count, the last and the one "
                  "before the first break; otherwise four frames spread over the run); at most 24, each a "
                  "damage and a displacement map",
                  default=None, unit="s"),
        dpi=Key("integer", "resolution of the PNG figures in dots per inch: 300 prints sharp; 100–150 for "
                "the screen (smaller files); the layout in points is the same at every value",
                default=300, minimum=50, maximum=1200),
        displacement_component=Key("choice", "displacement component coloured in the maps",
                                   default="x", choices=("x", "y", "z")),
        probe=Key("point_or_name", "where probe.png follows the displacement component: a point "
                  "[x, y] or [x, y, z] (the node nearest to it), or a node-set name (the mean over its "
                  "nodes); default: the first set of output.probes, else the node nearest the centre of the "
                  "bounding box. A set of output.probes is drawn from every history row, anything else from "
                  "the frames", default=None, unit="m"),
    ),
}


def markdown() -> str:
    """The case-file reference, generated from CASE."""
    rows = ["# Case file reference", "",
            "Generated from pipeline/schema.py by `/usr/bin/python3 -m pipeline.schema`; "
            "do not edit by hand. SI units throughout.", "",
            "| key | type | default | unit | meaning |", "|---|---|---|---|---|"]

    def fmt_default(key: Key) -> str:
        if key.required:
            return "**required**"
        if key.default is None or key.default == {} or key.default == []:
            return "–"
        return f"`{key.default}`"

    def kind_text(key: Key) -> str:
        if key.kind == "point_or_name":
            return "point or name"
        if key.kind in ("choice", "number_or_choice"):
            extra = " or number" if key.kind == "number_or_choice" else ""
            return " \\| ".join(str(c) for c in key.choices) + extra
        return key.kind

    def emit(keys: dict, prefix: str):
        for name, key in keys.items():
            path = f"{prefix}{name}"
            rows.append(f"| `{path}` | {kind_text(key)} | {fmt_default(key)} | {key.unit} | {key.doc} |")
            if key.kind == "section":
                emit(key.fields, path + ".")
            elif key.kind == "named":
                emit(key.fields, path + ".<name>.")
            elif key.kind == "list":
                emit(key.fields, path + "[].")

    emit(CASE, "")
    return "\n".join(rows) + "\n"


if __name__ == "__main__":
    print(markdown(), end="")
