// Every key of case.json's settings sections, declared once: name, type and default (the field it
// is read into), range, choices, unit. What the ranges mean: core/case.hpp, beside each field.
#include "io/case_settings.hpp"

#include "integrators/integrator.hpp"
#include "io/output.hpp"

namespace pd {

namespace {

// Newton's block (core/case.hpp NewtonSettings), the same in quasi_static and implicit but for the
// name of its correction tolerance: "tol" in quasi_static, "newton_tol" in implicit (whose tol is
// the step's error tolerance).
std::vector<Setting> newton_settings(NewtonSettings& n, const std::string& tol_key) {
  return {
      fraction(tol_key, n.newton_tol, "a relative error"),
      fraction("residual_tol", n.residual_tol, "a relative error"),
      integer("kd", n.kd, 1, 1000),
      positive("p", n.p),
      integer("max_iterations", n.max_iterations, 1, 100000),
      choice("linear_solver", n.linear_solver, {"auto", "direct", "cg"}),
      integer("cg_max_iterations", n.cg_max_iterations, 1, 100000000),
      positive("dt_initial", n.dt_initial).in_unit("s"),
      positive("dt_min", n.dt_min).in_unit("s"),
      positive("dt_max", n.dt_max).in_unit("s"),
  };
}

// A table followed by more keys.
std::vector<Setting> joined(std::vector<Setting> first, const std::vector<Setting>& then) {
  first.insert(first.end(), then.begin(), then.end());
  return first;
}

}  // namespace

std::vector<SettingsSection> settings_sections(Case& c) {
  TimeSettings& t = c.time;
  AdaptiveSettings& a = c.adaptive;
  QuasiStaticSettings& q = c.quasi_static;
  ImplicitSettings& im = c.implicit;
  MixedSettings& m = c.mixed;
  OutputSettings& o = c.output;
  ContactSettings& k = c.contact;

  return {
      {"contact", false, "",
       {choice("enabled", k.enabled, {"auto", "on", "off"}),
        flag("self_contact", k.self_contact),
        positive("skin", k.skin).in_unit("m").with_note("absent or null: half the grid spacing").null_means_default(),
        positive("stiffness_factor", k.stiffness_factor)}},
      {"time", true, "",
       {positive("end", t.end).in_unit("s").needed(),
        choice("integrator", t.integrator, integrator_registry().keys()).called("integrator"),
        rule_or_positive("dt", t.dt_rule, t.dt_value, {"stable", "exact"}).in_unit("s"),
        positive("safety_factor", t.safety_factor),
        integer("max_steps", t.max_steps, 1)}},
      {"adaptive", false, "",
       {fraction("tol", a.tol, "a relative error"),
        integer("kd", a.kd, 1, 1000),
        positive("p", a.p),
        between("phi", a.phi, 0.5, 1.0),
        positive("dt_initial", a.dt_initial).in_unit("s"),
        positive("dt_min", a.dt_min).in_unit("s"),
        positive("dt_max", a.dt_max).in_unit("s")}},
      {"quasi_static", false, "",
       joined(newton_settings(q, "tol"),
              {integer("max_breaking_rounds", q.max_breaking_rounds, 1, 100000000),
               flag("cut_to_first_failure", q.cut_to_first_failure),
               choice("preconditioner", q.preconditioner, {"auto", "block_jacobi", "amg"})})},
      {"implicit", false, "",
       joined({between("rho_infinity", im.rho_infinity, 0.0, 1.0, "1: no numerical dissipation"),
               fraction("tol", im.tol, "a relative error")},
              newton_settings(im, "newton_tol"))},
      {"mixed", false, "",
       {choice("start", m.start, {"quasi_static", "implicit"}),
        integer("unstable_rounds", m.unstable_rounds, 1, 100000000),
        fraction("kinetic_fraction", m.kinetic_fraction, "a fraction of the strain energy"),
        integer("arrest_steps", m.arrest_steps, 1, 1000000000)}},
      {"output", true, "exactly one of every_time and every_steps",
       {positive("every_time", o.every_time).in_unit("s"),
        integer("every_steps", o.every_steps, 1),
        integer("history_every", o.history_every, 1),
        names("reactions", o.reactions).with_note("each one of node_sets"),
        names("probes", o.probes).with_note("each one of node_sets"),
        positive("restart_every_time", o.restart_every_time).in_unit("s"),
        integer("restart_every_steps", o.restart_every_steps, 1),
        non_negative("restart_every_wall", o.restart_every_wall).in_unit("s").with_note("wall time; 0: none"),
        choice("precision", o.precision, {"float32", "float64"}),
        choice("compression", o.compression, {"zlib", "none"}),
        names("fields", o.fields, frame_fields()).called("field"),
        choice("gmsh", o.gmsh, {"all", "figures", "none"}).with_note("postprocess only: checked to be one of the choices"),
        choice("parallel_frames", o.parallel_frames, {"gathered", "pieces"}).with_note("several MPI ranks only")}},
  };
}

}  // namespace pd
