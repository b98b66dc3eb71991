// pdsolve --describe: the case.json keys the reader accepts, described from the structs' own
// defaults (core/case.hpp) and the registries' keys, checked against the reader's key lists.
#include "io/describe.hpp"

#include <optional>
#include <set>
#include <string>

#include "core/case.hpp"
#include "core/error.hpp"
#include "core/material.hpp"
#include "core/partial_volume.hpp"
#include "core/surface_correction.hpp"
#include "forces/indenter.hpp"
#include "integrators/integrator.hpp"
#include "io/case_reader.hpp"
#include "io/output.hpp"

namespace pd {

namespace {

using json = nlohmann::json;

template <class T>
json value_or_null(const std::optional<T>& v) {
  return v ? json(*v) : json(nullptr);
}

json spec(const std::string& type, json extra = json::object()) {
  json s = {{"type", type}};
  s.update(extra);
  return s;
}
json required(const std::string& type, json extra = json::object()) {
  extra["required"] = true;
  return spec(type, std::move(extra));
}
json defaulted(const std::string& type, json value, json extra = json::object()) {
  extra["default"] = std::move(value);
  return spec(type, std::move(extra));
}

}  // namespace

json describe_case() {
  const Case c;
  const TimeSettings t;
  const AdaptiveSettings a;
  const OutputSettings o;
  const ContactSettings k;
  const InitialCondition ic;
  const IndenterSettings ind;
  const json positive = {{"above", 0.0}};

  // Ranges and hand-checked choices as case_reader.cpp enforces them (time.max_steps and the other
  // counts have no maximum but int64's); defaults from the structs.
  json keys = json::object();
  keys["format_version"] = required("integer", {{"choices", {kCaseFormatVersion}}});
  keys["case"] = defaulted("string", c.name);
  keys["title"] = defaulted("string", c.title);
  keys["source"] = defaulted("string", c.source);
  keys["nodes_file"] = required("string", {{"note", "relative to the directory of case.json; not empty"}});
  keys["output_dir"] = defaulted("string", kDefaultOutputDir, {{"note", "relative to the directory of case.json (the run folder), and inside it: an absolute path, .. out of it or a symbolic link out of it is refused"}});
  keys["dimension"] = required("integer", {{"minimum", 2}, {"maximum", 3}});
  keys["analysis"] = required("string", {{"choices", analysis_registry().keys()}, {"note", "must fit dimension"}});
  keys["thickness"] = defaulted("number", c.thickness,
                              {{"above", 0.0}, {"unit", "m"}, {"required_if", "dimension == 2"},
                               {"note", "unused in 3D"}});
  keys["grid_spacing"] = required("number", {{"above", 0.0}, {"unit", "m"}});
  keys["horizon"] = required("number", {{"above", 0.0}, {"unit", "m"}});
  keys["partial_volume"] = defaulted("string", c.partial_volume, {{"choices", partial_volume_registry().keys()}});
  keys["surface_correction"] = defaulted("string", c.surface_correction,
                                         {{"choices", surface_correction_registry().keys()}});
  keys["blocks"] = required("list", {{"note", "at least one; blocks[k].id == k + 1"}});
  keys["blocks[].id"] = required("integer", {{"minimum", 1}, {"note", "its position, counted from 1"}});
  keys["blocks[].name"] = required("string");
  keys["no_fail_sets"] = defaulted("strings", c.no_fail_sets);
  keys["node_sets"] = defaulted("strings", c.node_sets);
  keys["boundary_conditions"] = defaulted("list", json::array());
  keys["boundary_conditions[].set"] = required("string");
  keys["boundary_conditions[].kind"] = required("string", {{"choices", {"displacement", "velocity", "body_force"}}});
  keys["boundary_conditions[].component"] = required("integer", {{"minimum", 0}, {"maximum", 2}});
  keys["boundary_conditions[].times"] = required("numbers", {{"unit", "s"}, {"note", "strictly increasing, not empty"}});
  keys["boundary_conditions[].values"] = required("numbers", {{"note", "as many as times"}});
  keys["initial_conditions"] = defaulted("list", json::array());
  keys["initial_conditions[].set"] = required("string");
  keys["initial_conditions[].kind"] = required("string", {{"choices", {"displacement", "velocity"}}});
  keys["initial_conditions[].component"] = required("integer", {{"minimum", 0}, {"maximum", 2}});
  keys["initial_conditions[].value"] = required("number");
  keys["initial_conditions[].gradient"] = defaulted("number", ic.gradient, {{"note", "kind displacement only: u = value + gradient·x[component]"}});
  keys["cracks"] = defaulted("list", json::array());
  keys["cracks[].from"] = required("numbers", {{"length", 3}, {"unit", "m"}});
  keys["cracks[].to"] = required("numbers", {{"length", 3}, {"unit", "m"}});
  keys["breaking_order"] = defaulted("string", c.breaking_order, {{"choices", {"thesis", "lammps"}}});
  keys["damping"] = defaulted("number", c.damping, {{"minimum", 0.0}, {"unit", "1/s"}});
  keys["contact"] = defaulted("object", json::object());
  keys["contact.enabled"] = defaulted("string", k.enabled, {{"choices", {"auto", "on", "off"}}});
  keys["contact.self_contact"] = defaulted("boolean", k.self_contact);
  keys["contact.skin"] = defaulted("number", k.skin,
                                 {{"above", 0.0}, {"unit", "m"}, {"note", "absent or null: half the grid spacing"}});
  keys["contact.stiffness_factor"] = defaulted("number", k.stiffness_factor, positive);
  keys["indenters"] = defaulted("list", json::array());
  keys["indenters[].name"] = required("string", {{"note", "[A-Za-z_][A-Za-z0-9_]*, unique"}});
  keys["indenters[].shape"] = required("string", {{"choices", indenter_shape_registry().keys()}});
  keys["indenters[].radius"] = defaulted("number", ind.radius,
                                       {{"above", 0.0}, {"unit", "m"}, {"required_if", "shape != plane"}});
  keys["indenters[].centre"] = required("numbers", {{"length", 3}, {"unit", "m"}});
  keys["indenters[].velocity"] = defaulted("numbers", ind.velocity, {{"length", 3}, {"unit", "m/s"}});
  keys["indenters[].normal"] = defaulted("numbers", ind.normal,
                                       {{"length", 3}, {"required_if", "shape == plane"}, {"note", "made a unit vector"}});
  keys["indenters[].axis"] = defaulted("numbers", kDefaultCylinderAxis,
                                     {{"length", 3}, {"note", "cylinder only; made a unit vector"}});
  keys["indenters[].stiffness"] = required("number", {{"above", 0.0}, {"unit", "N/m⁵"}});
  keys["time"] = required("object");
  keys["time.end"] = required("number", {{"above", 0.0}, {"unit", "s"}});
  keys["time.integrator"] = defaulted("string", t.integrator, {{"choices", integrator_registry().keys()}});
  keys["time.dt"] = defaulted("number_or_choice", t.dt_rule,
                            {{"choices", {"stable", "exact"}}, {"above", 0.0}, {"unit", "s"}});
  keys["time.safety_factor"] = defaulted("number", t.safety_factor, positive);
  keys["time.max_steps"] = defaulted("integer", t.max_steps, {{"minimum", 1}});
  keys["adaptive"] = defaulted("object", json::object());
  keys["adaptive.tol"] = defaulted("number", a.tol, {{"above", 0.0}, {"below", 1.0}});
  keys["adaptive.kd"] = defaulted("integer", a.kd, {{"minimum", 1}, {"maximum", 1000}});
  keys["adaptive.p"] = defaulted("number", a.p, positive);
  keys["adaptive.phi"] = defaulted("number", a.phi, {{"minimum", 0.5}, {"maximum", 1.0}});
  keys["adaptive.dt_initial"] = defaulted("number", value_or_null(a.dt_initial), {{"above", 0.0}, {"unit", "s"}});
  keys["adaptive.dt_min"] = defaulted("number", value_or_null(a.dt_min), {{"above", 0.0}, {"unit", "s"}});
  keys["adaptive.dt_max"] = defaulted("number", value_or_null(a.dt_max), {{"above", 0.0}, {"unit", "s"}});
  const QuasiStaticSettings q{};
  keys["quasi_static"] = defaulted("object", json::object());
  keys["quasi_static.tol"] = defaulted("number", q.tol, {{"above", 0.0}, {"below", 1.0}});
  keys["quasi_static.residual_tol"] = defaulted("number", q.residual_tol, {{"above", 0.0}, {"below", 1.0}});
  keys["quasi_static.kd"] = defaulted("integer", q.kd, {{"minimum", 1}, {"maximum", 1000}});
  keys["quasi_static.p"] = defaulted("number", q.p, positive);
  keys["quasi_static.max_iterations"] = defaulted("integer", q.max_iterations, {{"minimum", 1}, {"maximum", 100000}});
  keys["quasi_static.max_breaking_rounds"] =
      defaulted("integer", q.max_breaking_rounds, {{"minimum", 1}, {"maximum", 100000000}});
  keys["quasi_static.cut_to_first_failure"] = defaulted("boolean", q.cut_to_first_failure);
  keys["quasi_static.linear_solver"] = defaulted("string", q.linear_solver, {{"choices", {"auto", "direct", "cg"}}});
  keys["quasi_static.preconditioner"] =
      defaulted("string", q.preconditioner, {{"choices", {"auto", "block_jacobi", "amg"}}});
  keys["quasi_static.cg_max_iterations"] =
      defaulted("integer", q.cg_max_iterations, {{"minimum", 1}, {"maximum", 100000000}});
  keys["quasi_static.dt_initial"] = defaulted("number", value_or_null(q.dt_initial), {{"above", 0.0}, {"unit", "s"}});
  keys["quasi_static.dt_min"] = defaulted("number", value_or_null(q.dt_min), {{"above", 0.0}, {"unit", "s"}});
  keys["quasi_static.dt_max"] = defaulted("number", value_or_null(q.dt_max), {{"above", 0.0}, {"unit", "s"}});
  const ImplicitSettings im{};
  keys["implicit"] = defaulted("object", json::object());
  keys["implicit.rho_infinity"] = defaulted("number", im.rho_infinity, {{"minimum", 0.0}, {"maximum", 1.0}});
  keys["implicit.tol"] = defaulted("number", im.tol, {{"above", 0.0}, {"below", 1.0}});
  keys["implicit.newton_tol"] = defaulted("number", im.newton_tol, {{"above", 0.0}, {"below", 1.0}});
  keys["implicit.residual_tol"] = defaulted("number", im.residual_tol, {{"above", 0.0}, {"below", 1.0}});
  keys["implicit.kd"] = defaulted("integer", im.kd, {{"minimum", 1}, {"maximum", 1000}});
  keys["implicit.p"] = defaulted("number", im.p, positive);
  keys["implicit.max_iterations"] = defaulted("integer", im.max_iterations, {{"minimum", 1}, {"maximum", 100000}});
  keys["implicit.dt_initial"] = defaulted("number", value_or_null(im.dt_initial), {{"above", 0.0}, {"unit", "s"}});
  keys["implicit.dt_min"] = defaulted("number", value_or_null(im.dt_min), {{"above", 0.0}, {"unit", "s"}});
  keys["implicit.dt_max"] = defaulted("number", value_or_null(im.dt_max), {{"above", 0.0}, {"unit", "s"}});
  keys["implicit.linear_solver"] = defaulted("string", im.linear_solver, {{"choices", {"auto", "direct", "cg"}}});
  keys["implicit.cg_max_iterations"] =
      defaulted("integer", im.cg_max_iterations, {{"minimum", 1}, {"maximum", 100000000}});
  const MixedSettings mx{};
  keys["mixed"] = defaulted("object", json::object());
  keys["mixed.start"] = defaulted("string", mx.start, {{"choices", {"quasi_static", "implicit"}}});
  keys["mixed.unstable_rounds"] = defaulted("integer", mx.unstable_rounds, {{"minimum", 1}, {"maximum", 100000000}});
  keys["mixed.kinetic_fraction"] = defaulted("number", mx.kinetic_fraction, {{"above", 0.0}, {"below", 1.0}});
  keys["mixed.arrest_steps"] = defaulted("integer", mx.arrest_steps, {{"minimum", 1}, {"maximum", 1000000000}});
  keys["output"] = required("object", {{"note", "exactly one of every_time and every_steps"}});
  keys["output.every_time"] = defaulted("number", value_or_null(o.every_time), {{"above", 0.0}, {"unit", "s"}});
  keys["output.every_steps"] = defaulted("integer", value_or_null(o.every_steps), {{"minimum", 1}});
  keys["output.history_every"] = defaulted("integer", o.history_every, {{"minimum", 1}});
  keys["output.reactions"] = defaulted("strings", o.reactions, {{"note", "each one of node_sets"}});
  keys["output.restart_every_time"] = defaulted("number", value_or_null(o.restart_every_time),
                                              {{"above", 0.0}, {"unit", "s"}});
  keys["output.restart_every_steps"] = defaulted("integer", value_or_null(o.restart_every_steps), {{"minimum", 1}});
  keys["output.restart_every_wall"] = defaulted("number", o.restart_every_wall,
                                              {{"minimum", 0.0}, {"unit", "s"}, {"note", "wall time; 0: none"}});
  keys["output.precision"] = defaulted("string", o.precision, {{"choices", {"float32", "float64"}}});
  keys["output.compression"] = defaulted("string", o.compression, {{"choices", {"zlib", "none"}}});
  keys["output.fields"] = defaulted("strings", o.fields, {{"choices", frame_fields()}});
  keys["output.gmsh"] = defaulted("string", o.gmsh, {{"choices", {"all", "figures", "none"}},
                                                     {"note", "postprocess only: checked to be one of the choices"}});
  keys["output.parallel_frames"] = defaulted("string", o.parallel_frames, {{"choices", {"gathered", "pieces"}},
                                                                           {"note", "several MPI ranks only"}});
  keys["figures"] = defaulted("object", json::object(), {{"note", "postprocess only: checked to be an object"}});

  // Every key the reader accepts is described, and nothing else (blocks: id, name + the material's).
  std::set<std::string> accepted = {"blocks[].id", "blocks[].name"};
  const json material = describe_material_keys();  // a named object: items() does not extend a temporary
  for (const auto& item : material.items()) {
    keys["blocks[]." + item.key()] = item.value();
    accepted.insert("blocks[]." + item.key());
  }
  for (const auto& [where, names] : case_keys())
    for (const auto& name : names) accepted.insert(where.empty() ? name : where + "." + name);
  for (const auto& item : keys.items())
    if (!accepted.count(item.key())) throw Error("describe: '" + item.key() + "' is not a key case_reader accepts");
  for (const auto& name : accepted)
    if (!keys.contains(name)) throw Error("describe: the reader accepts '" + name + "', which is not described");

  return {{"describe_version", 1},
          {"keys", keys},
          {"registries",
           {{"analysis", analysis_registry().keys()},
            {"integrator", integrator_registry().keys()},
            {"partial_volume", partial_volume_registry().keys()},
            {"surface_correction", surface_correction_registry().keys()},
            {"indenter_shape", indenter_shape_registry().keys()}}}};
}

}  // namespace pd
