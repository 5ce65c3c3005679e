#include "runtime/record/summary.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/stats.h"
#include "runtime/record/budget_report.h"
#include "runtime/session/cut_region.h"
#include "runtime/session/device_factory.h"
#include "runtime/record/material_report.h"

namespace palpate {
namespace {

nlohmann::json ms_json(const std::vector<double>& v) {
  return {{"p50", percentile(v, 0.5)}, {"p99", percentile(v, 0.99)}, {"max", percentile(v, 1.0)}, {"count", v.size()}};
}

nlohmann::json hist_json(const LatencyHistogram& h) {
  const std::string over = "over_" + std::to_string(static_cast<int64_t>(h.range_us() / 1000.0)) + "ms";
  return {{"p50", h.quantile_us(0.5)}, {"p99", h.quantile_us(0.99)}, {"p999", h.quantile_us(0.999)},
          {"max", h.max_us()}, {"count", h.count()}, {over, h.overflow()}};
}

double per_frame(int64_t sum, int64_t frames) {
  return static_cast<double>(sum) / static_cast<double>(std::max<int64_t>(1, frames));
}

nlohmann::json profile_entry(const FrameProfile& f) {
  nlohmann::json wall, cpu;
  for (int p = 0; p < kFrameParts; ++p) {
    wall[kFramePartNames[p]] = f.wall_ms[p];
    cpu[kFramePartNames[p]] = f.cpu_ms[p];
  }
  return {{"frame", f.frame},         {"ms", f.frame_wall_ms},       {"cpu_ms", f.frame_cpu_ms},
          {"involuntary_switches", f.involuntary_switches},          {"iterations", f.iterations},
          {"springs_cut", f.springs_cut}, {"parts_ms", wall},        {"parts_cpu_ms", cpu}};
}

// Where the sim's frame time went: each part's percentiles over all frames (wall and CPU), and the slowest
// frames part by part.
nlohmann::json profile_json(const std::vector<FrameProfile>& frames) {
  static constexpr std::size_t kSlowest = 10;
  nlohmann::json wall, cpu;
  std::vector<double> v;
  v.reserve(frames.size());
  for (int p = 0; p < kFrameParts; ++p) {
    v.clear();
    for (const FrameProfile& f : frames) v.push_back(f.wall_ms[p]);
    wall[kFramePartNames[p]] = ms_json(v);
    v.clear();
    for (const FrameProfile& f : frames) v.push_back(f.cpu_ms[p]);
    cpu[kFramePartNames[p]] = ms_json(v);
  }
  std::vector<const FrameProfile*> order;
  for (const FrameProfile& f : frames) order.push_back(&f);
  const std::size_t n = std::min(kSlowest, order.size());
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(n), order.end(),
                    [](const FrameProfile* a, const FrameProfile* b) { return a->frame_wall_ms > b->frame_wall_ms; });
  nlohmann::json slowest = nlohmann::json::array();
  for (std::size_t i = 0; i < n; ++i) slowest.push_back(profile_entry(*order[i]));
  return {{"parts_ms", wall}, {"parts_cpu_ms", cpu}, {"slowest_frames", slowest}};
}

}  // namespace

nlohmann::json recording_summary(const SummaryInputs& in) {
  const Scene& scene = *in.scene;
  const Model& model = *in.model;
  const Session& session = *in.session;
  const FrameStage& stage = session.stage();
  const FrameStats& fst = stage.stats();
  const ServoCounters& sc = session.servo().counters();
  const ServoParams& sp = session.servo_params();
  const ServoTiming& timing = in.run->timing;
  const double rate_hz = session.rates().servo_hz;
  const CouplingLimit coupling = coupling_limit(scene, in.device->specs());
  const PngWriter* writer = in.writer;

  nlohmann::json j;
  j["scene"] = scene.path;
  j["mode"] = name_of(in.lockstep ? RunMode::kLockstep : RunMode::kRealtime);
  j["interaction"] = mode_name(scene.mode);
  j["duration_s"] = scene.duration_s;
  j["model"] = {{"vertices", model.rest.vertices_m.size()}, {"triangles", model.rest.triangles.size()},
                {"startup_s", in.startup_s}};
  if (const std::string turned = model.orientation.notice(); !turned.empty()) j["model"]["orientation"] = turned;
  if (model.auto_subdivisions > 0) j["model"]["subdivided_on_load"] = model.auto_subdivisions;
  // what the material became on the lattice (nu represented, total mass)
  if (scene.lattice.material.enabled) j["material"] = material_summary(scene, model.grid);
  // what a person changed while the run went on (the browser page's controls): the model started again after each
  if (!session.control_changes().empty()) {
    nlohmann::json changes = nlohmann::json::array();
    for (const ControlChange& c : session.control_changes())
      changes.push_back({{"frame", c.frame},
                         {"t_s", c.t_s},
                         {"seq", c.controls.seq},
                         {"mode", mode_name(c.controls.mode)},
                         {"stiffness_scale", c.controls.stiffness_scale},
                         {"tool_radius_m", c.controls.tool_radius_m},
                         {"resets", c.controls.resets}});
    j["controls"] = changes;
  }
  if (!in.run->aborted.empty()) j["aborted"] = in.run->aborted;
  if (!in.run->interrupted.empty()) j["interrupted"] = in.run->interrupted;
  j["frames_written"] = writer ? writer->frames_written() : 0;
  j["frames_dropped"] = fst.frames_dropped;
  j["servo_ticks"] = sc.ticks;
  j["max_force_N"] = sc.max_force_N;
  if (!in.no_contact.empty()) j["no_contact"] = in.no_contact;
  j["max_displacement_m"] = fst.max_displacement_m;
  // touch mode: a free tool deeper inside the object than the material has moved (a touch lost)
  if (scene.mode == InteractionMode::kTouch)
    j["tool_inside"] = {{"frames", fst.tool_inside_frames},
                        {"first_t_s", fst.tool_inside_frames > 0 ? nlohmann::json(fst.tool_inside_first_t_s) : nlohmann::json()},
                        {"depth_m", fst.tool_inside_depth_m},
                        {"ticks", fst.tool_inside_ticks},
                        {"proxy_ticks", fst.proxy_inside_ticks},
                        {"first_tick_t_s", fst.through_first_t_s >= 0.0 ? nlohmann::json(fst.through_first_t_s) : nlohmann::json()}};
  j["nan_events"] = fst.nan_events;
  j["dropped_samples"] = sc.dropped_samples;
  j["rejected_inputs"] = sc.rejected_inputs;
  j["no_readings"] = sc.no_readings;
  // the coupling used and the limit that set it: the scene's ask, a stiffness limit, or the passivity bound
  // 2b/T at this rate (b the device's damping)
  j["coupling"] = {{"stiffness_N_per_m", sp.coupling_N_per_m},
                   {"capped", sp.coupling_N_per_m < scene.device.coupling_N_per_m},
                   {"bound", coupling.bound},
                   {"limits_N_per_m", {{"scene", coupling.scene_N_per_m},
                                       {"scene_max", coupling.scene_max_N_per_m},
                                       {"device_max", coupling.device_max_N_per_m},
                                       {"passivity", coupling.passivity_max_N_per_m}}},
                   {"device_damping_Ns_per_m", coupling.damping_Ns_per_m},
                   {"passivity", sp.passivity},
                   {"passivity_activations", sc.passivity_activations},
                   {"passivity_dissipated_J", sc.passivity_dissipated_J},
                   {"ramps", sc.ramps}};
  j["haptic_rows"] = in.haptic_rows;
  j["servo"] = {{"clock", in.lockstep ? "virtual" : "wall"},
                {"latency_us", hist_json(timing.wake_latency)},
                {"compute_us", hist_json(timing.compute)},
                {"overruns", timing.overruns},
                {"first_overrun_ticks", std::vector<int64_t>(timing.first_overrun_ticks.begin(),
                                                             timing.first_overrun_ticks.begin() + timing.overrun_ticks_recorded)},
                {"rate_hz", rate_hz},
                {"rate_from", in.rate_given ? "--servo-rate" : "scene"},
                {"spin_us", timing.spin.final_ns / 1000}, {"spin_adaptive", timing.spin.adaptive},
                {"steal_ms", timing.steal_ms >= 0 ? nlohmann::json(timing.steal_ms) : nlohmann::json()},
                {"involuntary_switches", timing.involuntary_switches >= 0 ? nlohmann::json(timing.involuntary_switches) : nlohmann::json()},
                {"rt", {{"memory_locked", in.run->memory_locked}, {"sched_fifo", timing.rt.fifo}, {"priority", timing.rt.priority},
                        {"cpu", timing.rt.cpu}, {"timer_slack_1ns", timing.rt.timer_slack_1ns}, {"refused", timing.rt.refused}}}};
  j["sim"] = {{"ms", ms_json(fst.sim_ms)},
              {"cpu_ms", ms_json(fst.sim_cpu_ms)},
              {"integrator", integrator_name(scene.lattice.integrator)},
              {"max_substeps", fst.max_substeps},
              // implicit Euler steps that failed whole (a squashed Neo-Hookean cell's tangent) and were split,
              // those no split could take, taken by projected Newton, and frames whose solver failed even so and
              // stepped explicitly
              {"implicit_splits", fst.implicit_splits},
              {"projected_steps", fst.projected_steps},
              {"steps_out_of_time", fst.steps_out_of_time},
              {"solver_fallbacks", fst.solver_fallbacks},
              {"max_strain", fst.max_strain},
              {"nodes", fst.lattice_nodes},
              {"springs", fst.lattice_springs},
              {"vertices", fst.lattice_vertices},
              {"per_frame_mean", {{"nodes", per_frame(fst.node_frames, fst.frames)},
                                  {"springs", per_frame(fst.spring_frames, fst.frames)},
                                  {"vertices", per_frame(fst.vertex_frames, fst.frames)}}},
              {"step_ms", ms_json(fst.step_ms)},
              {"step_cpu_ms", ms_json(fst.step_cpu_ms)},
              {"frames_stepped", fst.frames_stepped},
              {"frames_resting", fst.frames_resting},
              {"region_moves", fst.region_moves},
              {"divergence_events", fst.divergence_events},
              {"frame_latency_us", hist_json(in.run->frame_latency)},
              {"frames_late", in.run->frames_late},
              {"skipped_frames", in.run->skipped_frames},
              {"profile", profile_json(fst.profile)}};
  // where the push went: solved under the tool's tip, or by formula (device.contact; a solved one falls back to the
  // formula until the lattice's stiffness is factored, and on a refined lattice)
  j["contact_load"] = {{"asked", scene.device.solved_contact ? "solved" : "prescribed"},
                       {"solved_frames", fst.solved_contact_frames},
                       {"prescribed_frames", fst.prescribed_contact_frames},
                       {"solved_radius_m", fst.solved_contact_radius_m},
                       // the servo's contact model between frames: the factored compliance, or an estimate above it
                       {"servo_models_factored", fst.contact_models},
                       {"servo_models_estimated", fst.contact_models_estimated}};
  if (scene.lattice.budget_ms > 0.0) j["budget"] = budget_summary(scene, stage, in.lockstep);
  if (scene.mode == InteractionMode::kCut) {
    const CutModel* cut = stage.cut_model();
    j["cut"] = {{"frames_cutting", fst.frames_cutting},
                {"springs_cut", fst.springs_cut},
                // under a budget a frame removes at most kBudgetSpringsPerFrame; the rest wait
                {"springs_deferred_max", fst.springs_deferred_max},
                {"frames_deferring", fst.frames_deferring},
                {"springs_left", stage.lattice() ? stage.lattice()->springs.size() : 0},
                {"triangles", cut ? cut->triangles().size() : 0},
                {"triangles_added", fst.triangles_added},
                {"vertices_added", fst.vertices_added},
                {"free_nodes", fst.free_nodes},
                // triangles plus vertices tested in one frame, at most kCutWorkPerFrame plus one quad's
                {"work_max", fst.cut_work_max},
                {"work_limit", kCutWorkPerFrame},
                {"sim_ms_cutting", ms_json(fst.cutting_ms)},
                {"sim_ms_after_cut", ms_json(fst.after_cut_ms)},
                // per frame from the first cut on: what the cut and the pieces' motion made the mesh recompute (counts)
                {"vertices_deformed", ms_json(fst.cut_vertices_deformed)},
                {"normals_recomputed", ms_json(fst.cut_normals)}};
  }
  j["render"] = {{"ms", ms_json(fst.render_ms)}, {"cpu_ms", ms_json(fst.render_cpu_ms)},
                 {"layer_build_ms", ms_json(fst.layer_build_ms)}, {"layer_build_cpu_ms", ms_json(fst.layer_build_cpu_ms)},
                 // pixels each layer build redrew (a part of the frame when only the moving part changed)
                 {"layer_build_px", ms_json(fst.layer_build_px)},
                 {"backend", in.gl ? in.gl->backend_name() : "none"},
                 {"width", scene.render.width}, {"height", scene.render.height},
                 {"frames_layered", fst.frames_layered}, {"layer_builds", in.renderer ? in.renderer->layer_builds() : 0},
                 {"layer_resplits", in.renderer ? in.renderer->resplits() : 0},
                 // layered frames that drew the moving part (the others copied its image: nothing in it changed)
                 {"dynamic_draws", in.renderer ? in.renderer->dynamic_draws() : 0}};
  if (in.renderer && scene.render.style == RenderStyle::kBoth) {
    // the wireframe is left out of `both` on a mesh finer than the image (render.wire_min_edge_px)
    const double median = in.renderer->median_edge_px();
    j["render"]["wire"] = {{"drawn", in.renderer->wire_drawn()},
                           {"median_edge_px", std::isfinite(median) ? nlohmann::json(median) : nlohmann::json(nullptr)},
                           {"min_edge_px", scene.render.wire_min_edge_px}};
  }
  // what the frames show besides the model: displacement colours (their range, fixed before the first frame or
  // followed), the force arrow, the legend
  const bool strain = colors_by_strain(scene);
  j["render"]["color"] = {{"by", strain ? "strain" : colors_by_displacement(scene) ? "displacement" : "none"},
                          // metres, or a fraction when coloured by strain
                          {strain ? "range" : "range_m", stage.view_style().range()},
                          {"range_fixed", stage.view_style().fixed()},
                          // the largest distance from rest of a point the frames drew
                          {"max_displacement_m", stage.view_style().shown_max_m()},
                          {"max_strain", stage.view_style().shown_max_strain()},
                          {"force_arrow", scene.render.force_arrow},
                          {"legend", scene.render.legend},
                          {"floor", scene.render.floor},
                          // samples a pixel the frames were drawn with (1: not multisampled), and whether their
                          // edges were smoothed in the image
                          {"samples", in.renderer ? std::max(1, in.renderer->samples()) : 0},
                          {"smooth_edges", in.renderer && in.renderer->smooth_edges()}};
  // a mesh finer than the image is drawn clustered (render.lod_min_edge_px)
  j["render"]["lod"] = {{"used", stage.lod() != nullptr}, {"min_edge_px", scene.render.lod_min_edge_px}};
  if (const MeshLod* lod = stage.lod()) {
    j["render"]["lod"].update({{"triangles", lod->triangles.size()},
                               {"vertices", lod->representatives},
                               {"median_edge_px", lod->median_edge_px},
                               {"lod_median_edge_px", lod->lod_median_edge_px},
                               {"max_shift_px", lod->max_shift_px}});
  }
  j["png"] = {{"ms", ms_json(writer ? writer->png_ms() : std::vector<double>{})},
              {"write_errors", writer ? writer->write_errors() : 0},
              {"threads", in.png.threads},
              {"codec", in.png.codec == PngCodec::kZlib ? "zlib" : "libdeflate"},
              {"keep_alpha", in.png.keep_alpha}};
  // realtime: which scene frame each file shows (files are numbered without gaps; lockstep: file i is frame i)
  if (!in.lockstep) j["frames_scene_index"] = fst.written_frames;
  j["video"] = video_json(*in.video, in.render ? "off: no video path (--no-video)" : "no frames (--no-render)");
  j["wall_s"] = in.wall_s;
  j["wall_s_per_scene_s"] = in.wall_s / scene.duration_s;
  if (in.lockstep) j["state_hash"] = stage.state_hash();
  j["device"] = in.device->report();
  j["outputs"] = {{"frames", in.render ? nlohmann::json(in.frames_dir) : nlohmann::json(nullptr)},
                  {"haptic_csv", in.haptic_csv.empty() ? nlohmann::json(nullptr) : nlohmann::json(in.haptic_csv)}};
  if (!in.haptic_error.empty()) j["outputs"]["haptic_csv_error"] = in.haptic_error;
  return j;
}

}  // namespace palpate
