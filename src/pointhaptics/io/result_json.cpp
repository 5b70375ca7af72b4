#include <pointhaptics/io/result_json.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/output_file.hpp>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>

namespace pointhaptics {
namespace {

using nlohmann::json;

json vec(const Eigen::Ref<const Vec3>& v) { return json::array({v[0], v[1], v[2]}); }

json columns(const Points& P) {
  json out = json::array();
  for (Eigen::Index i = 0; i < P.cols(); ++i) out.push_back(vec(P.col(i)));
  return out;
}

}  // namespace

std::string result_json(const Model& model, const State& state, const RunSummary& s) {
  json doc;
  json fixed = json::array(), active = json::array();
  for (index_t i = 0; i < model.n_points; ++i) {
    fixed.push_back(model.fixed[i] != 0);
    active.push_back(!s.lod.enabled || (i < static_cast<index_t>(s.lod.active.size()) && s.lod.active[i]));
  }
  doc["points"] = {
      {"reference", columns(model.X)}, {"displacement", columns(state.u)}, {"fixed", fixed}, {"active", active}};
  doc["solver"] = {{"kind", s.solver_kind},      {"converged", s.converged},
                   {"iterations", s.iterations}, {"residual", s.residual},
                   {"steps", s.steps},           {"substeps", s.substeps},
                   {"stable_dt", s.stable_dt},   {"cg_iterations", s.cg_iterations},
                   {"time", state.time}};
  if (!s.failure.empty()) doc["solver"]["failure"] = s.failure;
  doc["solver"]["inverted"] = s.inverted;
  doc["solver"]["inverted_steps"] = s.inverted_steps;
  doc["solver"]["collapsed"] = s.collapsed;
  if (s.interrupted) doc["solver"]["interrupted"] = true;
  if (s.solver_kind == "implicit") doc["solver"]["budget_steps"] = s.budget_steps;
  if (!s.preconditioner.empty()) doc["solver"]["preconditioner"] = s.preconditioner;
  if (s.preconditioner == "cholesky") {
    doc["solver"]["factorisations"] = s.factorisations;
    doc["solver"]["background_factorisations"] = s.background_factorisations;
    doc["solver"]["factor_bytes"] = s.factor_bytes;
  }
  if (s.preconditioner == "two_level") {
    doc["solver"]["coarse_points"] = s.coarse_points;
    doc["solver"]["factor_bytes"] = s.factor_bytes;
  }
  doc["energy"] = {{"strain", s.strain_energy}, {"kinetic", s.kinetic_energy}};
  doc["timing"] = {
      {"wall_s", s.wall_s},
      {"step_ms_mean", s.step_ms_mean},
      {"step_ms_max", s.step_ms_max},
      {"steps_per_s", s.steps_per_s},
      {"stages",
       {{"active_set_s", s.active_set_s}, {"tools_s", s.tools_s}, {"solve_s", s.solve_s}, {"contact_s", s.contact_s}}}};
  json constraints = json::array();
  for (size_t g = 0; g < model.fixed_groups.size(); ++g)
    constraints.push_back({{"points", model.fixed_groups[g].points.size()},
                           {"reaction", g < s.reactions.size() ? vec(s.reactions[g]) : vec(Vec3::Zero())}});
  doc["constraints"] = constraints;
  // zero without a probe
  const LocalModelSummary& m = s.local_model;
  doc["haptic"] = {{"ticks", s.haptic_ticks},
                   {"rate_hz", s.haptic_rate_hz},
                   {"period_p99_us", s.haptic_period_p99_us},
                   {"max_force_n", s.haptic_max_force_n},
                   {"min_observed_energy_j", s.haptic_min_observed_energy},
                   {"passivity_dissipated_j", s.haptic_passivity_dissipated},
                   {"passivity_ticks", s.haptic_passivity_ticks},
                   {"local_model",
                    {{"updates", m.updates},
                     {"force_mean_n", m.force_mean_n},
                     {"stray_mean_n", m.rendered_mean_n},
                     {"stray_max_n", m.rendered_max_n},
                     {"hold_stray_mean_n", m.hold_mean_n},
                     {"hold_stray_max_n", m.hold_max_n},
                     {"held_object_stray_mean_n", m.held_object_mean_n},
                     {"held_object_stray_max_n", m.held_object_max_n}}}};
  const auto tool_block = [&](const ToolSummary& t) {
    json block{{"kind", t.kind},
               {"position", vec(t.position)},
               {"force", vec(t.force)},
               {"torque", vec(t.torque)},
               {"contacts", t.contacts},
               {"penetration", t.penetration},
               {"friction", vec(t.friction)}};
    if (t.haptic_ticks > 0)
      block["haptic"] = {
          {"ticks", t.haptic_ticks}, {"period_p99_us", t.haptic_period_p99_us}, {"max_force_n", t.haptic_max_force_n}};
    return block;
  };
  if (s.tool.present) doc["tool"] = tool_block(s.tool);
  if (s.tool.present || !s.tools.empty()) {
    json& tools = doc["tools"] = json::object();
    if (s.tool.present) tools[s.tool_name] = tool_block(s.tool);
    for (const auto& [name, t] : s.tools) tools[name] = tool_block(t);
  }
  if (!s.obstacles.empty()) {
    json& obstacles = doc["obstacles"] = json::object();
    for (const auto& [name, o] : s.obstacles)
      obstacles[name] = {{"kind", o.kind},
                         {"force", vec(o.force)},
                         {"contacts", o.contacts},
                         {"penetration", o.penetration},
                         {"friction", vec(o.friction)}};
  }
  if (!s.bodies.empty()) {
    nlohmann::json& bodies = doc["bodies"] = nlohmann::json::object();
    for (const BodySummary& b : s.bodies) {
      json held = json::array();
      for (int g : b.constraints)
        held.push_back({{"index", g},
                        {"points", model.fixed_groups[static_cast<std::size_t>(g)].points.size()},
                        {"reaction", static_cast<std::size_t>(g) < s.reactions.size()
                                         ? vec(s.reactions[static_cast<std::size_t>(g)])
                                         : vec(Vec3::Zero())}});
      bodies[b.name] = {{"points", b.points},
                        {"mass", b.mass},
                        {"mean_displacement", vec(b.mean_displacement)},
                        {"max_displacement", b.max_displacement},
                        {"contact_force", vec(b.contact_force)},
                        {"constraints", held},
                        {"asleep", b.asleep},
                        {"slept_steps", b.slept_steps}};
    }
  }
  if (!s.bodies.empty() || s.body_contact.present)
    doc["body_contact"] = {{"pairs", s.body_contact.pairs},
                           {"contacts", s.body_contact.contacts},
                           {"penetration", s.body_contact.penetration}};
  if (s.cut.present) {
    const CutSummary& c = s.cut;
    doc["cut"] = {{"sweeps", c.sweeps},
                  {"cut_pairs", c.cut_pairs},
                  {"max_update_ms", c.max_update_ms},
                  {"mean_update_ms", c.mean_update_ms},
                  {"pieces", c.piece_points.size()},
                  {"piece_points", c.piece_points},
                  {"sheet_triangles", c.sheet_triangles},
                  {"surface_splits", c.surface_splits},
                  {"max_split_ms", c.max_split_ms}};
  }
  if (s.reduction.modes > 0) {
    const ReductionSummary& r = s.reduction;
    doc["reduction"] = {{"modes", r.modes},
                        {"linear_modes", r.linear_modes},
                        {"derivatives", r.derivatives},
                        {"load_vectors", r.load_vectors},
                        {"basis_spacing", r.basis_spacing},
                        {"setup_s", r.setup_s},
                        {"factorise_s", r.factorise_s},
                        {"modes_s", r.modes_s},
                        {"derivatives_s", r.derivatives_s},
                        {"polynomial_s", r.polynomial_s},
                        {"factor_mb", r.factor_bytes / 1e6},
                        {"tables_mb", r.tables_bytes / 1e6},
                        {"first_frequency_hz", r.first_frequency_hz},
                        {"cache_file", r.cache_file},
                        {"from_cache", r.from_cache},
                        {"cache_note", r.cache_note},
                        {"contact_points", r.contact_points},
                        {"contact_patches", r.contact_patches},
                        {"contact_hessians", r.contact_hessians}};
  }
  // without levels of detail every point is simulated
  const LodSummary& l = s.lod;
  doc["lod"] = {{"enabled", l.enabled},
                {"selected", l.enabled ? l.selected : model.n_points},
                {"selection_ms", l.selection_ms},
                {"frozen", l.frozen},
                {"widened", l.widened},
                {"band_count", l.band_count},
                {"band_selected", l.band_selected},
                {"selections", l.selections},
                {"build_ms", l.build_ms},
                {"max_reselect_ms", l.max_reselect_ms}};
  const ModelDiagnostics& d = model.diagnostics;
  doc["model"] = {{"points", model.n_points},
                  {"h", model.h},
                  {"kernel", std::string(to_string(model.kernel.type))},
                  {"volume", std::string(to_string(model.material.volume))},
                  {"total_volume", model.volume.sum()},
                  {"total_mass", model.mass.sum()},
                  {"mean_neighbours", d.mean_neighbours},
                  {"min_neighbours", d.min_neighbours},
                  {"regularised_neighbourhoods", d.regularised_neighbourhoods},
                  {"isolated_points", d.isolated_points},
                  {"severed_pairs", d.severed_pairs}};
  return doc.dump(1);
}

void write_result_json(const std::string& path, const Model& model, const State& state, const RunSummary& summary) {
  const std::string text = result_json(model, state, summary);
  write_text_file(path, "result JSON", [&](TextOutput& out) { out.print("{}\n", text); });
}

}  // namespace pointhaptics
