#include "tools/session/frame_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/state_hash.h"
#include "sim/cut.h"
#include "sim/region.h"
#include "sim/rest.h"

namespace palpate {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

FrameStage::FrameStage(const Scene& scene, const Model& model, SpscQueue<HapticSample>* samples,
                       TripleBuffer<LocalModel>* local_model, Renderer* renderer, PngWriter* writer, HapticLog* log)
    : scene_(scene),
      model_(model),
      samples_(samples),
      local_model_(local_model),
      renderer_(renderer),
      writer_(writer),
      log_(log),
      vertices_m_(model.rest.vertices_m) {
  latest_.tool_pos_m = scene.trajectory.front().pos_m;
  latest_.proxy_pos_m = latest_.tool_pos_m;
  stats_.sim_ms.reserve(static_cast<std::size_t>(scene.duration_s * 60.0) + 8);
  stats_.render_ms.reserve(stats_.sim_ms.capacity());
  if (scene.mode == InteractionMode::kCut) {
    cut_.emplace(model.rest, model.bindings, &model.grid, scene.lattice.level, scene.blade_length_m);
    build_cut_lattice();
  }
}

void FrameStage::set_step_dt(double dt_s) {
  const bool changed = dt_s != step_dt_s_;
  step_dt_s_ = dt_s;
  if (changed && cut_ && lattice_) prepare_step(*lattice_, step_opts_, step_dt_s_, &ws_);
}

void FrameStage::use_budget(BudgetClock* clock) {
  if (scene_.lattice.budget_ms <= 0.0) return;
  auto ladder = budget_ladder(step_options(scene_.lattice));
  if (ladder.empty()) return;
  budget_.emplace(scene_.lattice.budget_ms, std::move(ladder), clock);
}

void FrameStage::drain() {
  HapticSample s;
  while (samples_->try_pop(&s)) {
    if (log_) log_->append(s);
    if (live_) live_->add_sample(s);
    ++stats_.samples;
    ++frame_samples_;
    force_sum_N_ += s.force_N;
    if (s.contact != ContactState::kFree && s.contact_tri >= 0) {
      contact_ = s;
      contact_this_frame_ = true;
    }
    // the blade cuts whatever it sweeps while the button is held (the servo's in-material test only sets the
    // resistance: the lattice reaches past the surface, and its springs there must be cut too)
    if (cut_) cut_->add_sample(s.tool_pos_m, s.blade_axis, (s.buttons & 1u) != 0 && !s.input_rejected);
    latest_ = s;
  }
}

void FrameStage::drain_remaining() { drain(); }

void FrameStage::build_lattice_at(const Vec3& p_m) {
  const int level = scene_.lattice.level;
  const CellCoord center = model_.grid.cell_of(p_m, level);
  // a moved region keeps the old cells that are still deformed (beyond 1e-3 of a cell), so nothing snaps back
  const int radius = scene_.lattice.radius_cells;
  auto lat = build_lattice(model_.grid, scene_.lattice,
                           lattice_ ? followed_region_cells(model_.grid, *lattice_, center, radius, 1e-3 * lattice_->cell_m)
                                    : region_cells(model_.grid, level, center, radius));
  if (!lat) return;  // no solid cell near the contact: nothing to deform
  if (lattice_) {
    carry_state(*lattice_, &lat.value());
    // vertices of dropped cells go back to rest; the others are deformed again by the new lattice. Normals
    // that depended on the old region are final now unless they depend on the new one (redone after deform).
    for (int32_t v : deformer_.vertex_ids()) vertices_m_[v] = model_.rest.vertices_m[v];
    if (!normals_.empty() && !cut_) update_vertex_normals(vertices_m_, triangles(), model_.adjacency, normal_ids_, &normals_);
    ++stats_.region_moves;
  }
  lattice_ = std::move(lat).value();
  region_center_ = center;
  resting_ = false;
  step_opts_ = step_options(scene_.lattice);
  deformer_.attach(*lattice_, model_.bindings);
  if (!cut_) normal_dependents(triangles(), model_.adjacency, deformer_.vertex_ids(), &mark_scratch_, &normal_ids_);
  region_changed_ = true;
  ++layer_epoch_;
  f_ext_N_.assign(lattice_->num_nodes(), Vec3::Zero());
  stats_.lattice_nodes = std::max(stats_.lattice_nodes, lattice_->num_nodes());
  stats_.lattice_springs = std::max(stats_.lattice_springs, lattice_->springs.size());
  stats_.lattice_vertices = std::max(stats_.lattice_vertices, deformer_.num_bound_vertices());
}

void FrameStage::build_cut_lattice() {
  // the blade may go anywhere and cuts must persist: one lattice over every solid cell, never moved
  const int level = scene_.lattice.level;
  const int n = model_.grid.cells_per_axis(level);
  auto lat = build_lattice(model_.grid, scene_.lattice, region_cells(model_.grid, level, {n / 2, n / 2, n / 2}, n));
  if (!lat) return;
  lattice_ = std::move(lat).value();
  step_opts_ = step_options(scene_.lattice);
  f_ext_N_.assign(lattice_->num_nodes(), Vec3::Zero());
  floor_z_m_ = lattice_->rest_m.front().z();
  for (const Vec3& r : lattice_->rest_m) floor_z_m_ = std::min(floor_z_m_, r.z());
  stats_.lattice_nodes = lattice_->num_nodes();
  stats_.lattice_springs = lattice_->springs.size();
  stats_.lattice_vertices = vertices_m_.size();
  // the solver's factorisation too, before the first frame's deadline (the same one the first step would make)
  prepare_step(*lattice_, step_opts_, step_dt_s_, &ws_);
}

bool FrameStage::cut_frame() {
  if (!lattice_) return false;
  if (cut_->pending().empty()) return false;
  const CutReport rep = cut_->apply(&*lattice_, &vertices_m_);
  ++stats_.frames_cutting;
  stats_.springs_cut += rep.springs_cut;
  stats_.triangles_added += rep.split.triangles_added;
  stats_.vertices_added += rep.split.vertices_added;
  if (rep.springs_cut > 0) stats_.free_nodes = free_nodes(*lattice_);
  if (rep.changed()) {
    resting_ = false;
    normals_.clear();
  }
  return true;
}

void FrameStage::follow_contact() {
  if (!scene_.lattice.follow_contact || !contact_this_frame_ || contact_.contact_tri < 0) return;
  // the material point under the contact, at rest: its cell is where the contact force goes
  const auto& tri = model_.rest.triangles[static_cast<std::size_t>(contact_.contact_tri)];
  Vec3 p = Vec3::Zero();
  for (int c = 0; c < 3; ++c) p += contact_.contact_bary[c] * model_.rest.vertices_m[tri[c]];
  const CellCoord cell = model_.grid.cell_of(p, lattice_->level);
  if (contact_leaves_region(*lattice_, region_center_, cell, scene_.lattice.radius_cells)) build_lattice_at(p);
}

bool FrameStage::step_lattice_frame() {
  const bool pushed = max_force_N(f_ext_N_) >= scene_.lattice.rest_force_N;
  if (resting_ && !pushed) {
    ++stats_.frames_resting;
    return false;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpu_clock_.now_ms();
  if (budget_) budget_->step_begin();
  const StepReport rep = step_lattice(&*lattice_, frame_opts_ ? *frame_opts_ : step_opts_, step_dt_s_, f_ext_N_, &ws_);
  if (budget_) budget_->step_end();
  stats_.step_cpu_ms.push_back(cpu_clock_.now_ms() - c0);
  stats_.step_ms.push_back(ms_since(t0));
  ++stats_.frames_stepped;
  stats_.node_frames += static_cast<int64_t>(lattice_->num_nodes());
  stats_.spring_frames += static_cast<int64_t>(lattice_->springs.size());
  stats_.vertex_frames += static_cast<int64_t>(deformer_.num_bound_vertices());
  stats_.max_substeps = std::max(stats_.max_substeps, rep.substeps);
  stats_.substeps_total += rep.substeps;
  if (rep.diverged) {
    // a diverged state is counted and replaced by rest, so the run goes on
    ++(rep.finite ? stats_.divergence_events : stats_.nan_events);
    lattice_->reset_to_rest();
  }
  resting_ = !pushed && lattice_at_rest(*lattice_, f_ext_N_, scene_.lattice.rest_kinetic_J, scene_.lattice.rest_force_N,
                                        &rest_scratch_);
  return true;
}

PointWeights FrameStage::contact_weights(int32_t tri_id, const Vec3& bary) const {
  PointWeights w;
  const auto& tri = model_.rest.triangles[static_cast<std::size_t>(tri_id)];
  for (int c = 0; c < 3; ++c) {
    const VertexBinding& b = model_.bindings[static_cast<std::size_t>(tri[c])];
    const int32_t slot = lattice_->slot_of_cell[b.cell];
    if (slot < 0) continue;
    const auto tw = trilinear_weights(b.local);
    for (int k = 0; k < 8; ++k) {
      w.node[w.count] = lattice_->cell_nodes[slot][k];
      w.weight[w.count] = bary[c] * tw[k];
      ++w.count;
    }
  }
  return w;
}

PointWeights FrameStage::patch_weights(const HapticSample& s) const {
  const double radius = scene_.device.tool_radius_m;
  const auto& tri = model_.rest.triangles[static_cast<std::size_t>(s.contact_tri)];
  const Vec3& a0 = model_.rest.vertices_m[tri[0]];
  const Vec3& a1 = model_.rest.vertices_m[tri[1]];
  const Vec3& a2 = model_.rest.vertices_m[tri[2]];
  const Vec3 n = (a1 - a0).cross(a2 - a0).normalized();
  PointWeights w;
  if (!n.allFinite()) return w;
  // the patch is centred under the sphere's centre (its foot on the contact face's rest plane), not on the
  // servo's nearest surface point, which wanders over a patch the sphere has pressed into its own shape
  const double height = (s.proxy_pos_m - a0).dot(n);
  const Vec3 centre = s.proxy_pos_m - height * n;
  // depth of the sphere's lowest point below the rest surface, and the contact radius it gives
  const double depth = std::clamp(radius - height, 0.0, radius);
  const double a = std::sqrt(radius * depth);
  // the rings' orientation from a world axis, not the triangle: the same patch whichever triangle at a shared
  // vertex or edge holds the contact point this frame
  const Vec3 axis = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 t1 = (axis - axis.dot(n) * n).normalized(), t2 = n.cross(t1);
  const int level = lattice_->level;
  const double cell = lattice_->cell_m;
  // a hair inside the surface, so a sample on a face that lies on a cell plane lands in the solid cell
  const Vec3 in = -1e-3 * cell * n;
  double total = 0.0;
  auto sample = [&](const Vec3& p, double weight) {
    const int32_t slot = lattice_->slot_of_cell[model_.grid.linear_index(model_.grid.cell_of(p, level), level)];
    if (slot < 0 || !(weight > 0.0)) return;
    const auto& nodes = lattice_->cell_nodes[static_cast<std::size_t>(slot)];
    const Vec3 local = ((p - lattice_->rest_m[nodes[0]]) / cell).cwiseMax(0.0).cwiseMin(1.0);
    const auto tw = trilinear_weights(local);
    for (int k = 0; k < 8; ++k)
      if (!w.add(nodes[k], weight * tw[k])) return;
    total += weight;
  };
  // rings of samples, kRings annuli of equal width, each sample carrying pressure x its share of the area
  constexpr int kRings = 6;
  const double h = a / (kRings + 0.5);
  sample(centre + in, 0.25 * h * h * 3.14159265358979323846);
  for (int k = 1; k <= kRings && a > 0.0; ++k) {
    const double rho = k * h;
    const int count = 6 * k;
    const double share = 2.0 * 3.14159265358979323846 * rho * h / count;
    const double pressure = std::sqrt(std::max(0.0, 1.0 - rho * rho / (a * a)));
    for (int j = 0; j < count; ++j) {
      const double phi = 2.0 * 3.14159265358979323846 * (j + 0.5 * (k % 2)) / count;
      sample(centre + in + rho * (std::cos(phi) * t1 + std::sin(phi) * t2), share * pressure);
    }
  }
  if (!(total > 0.0)) return contact_weights(s.contact_tri, s.contact_bary);
  for (int i = 0; i < w.count; ++i) w.weight[i] /= total;
  return w;
}

Vec3 FrameStage::object_force(const Vec3& reaction_N) const {
  if (!scene_.device.sphere_tool || contact_.contact_tri < 0) return reaction_N;
  // a frictionless sphere pushes along the normal of the face under it (at rest: the tilt of the deformed facets
  // would swing a large sphere's centre sideways and back every frame)
  const auto& tri = model_.rest.triangles[static_cast<std::size_t>(contact_.contact_tri)];
  const Vec3& a0 = model_.rest.vertices_m[tri[0]];
  const Vec3 n = (model_.rest.vertices_m[tri[1]] - a0).cross(model_.rest.vertices_m[tri[2]] - a0).normalized();
  return n.allFinite() ? Vec3(n.dot(reaction_N) * n) : reaction_N;
}

PointWeights FrameStage::force_weights(const HapticSample& s) const {
  return scene_.device.sphere_tool ? patch_weights(s) : contact_weights(s.contact_tri, s.contact_bary);
}

int FrameStage::apply_contact_force(std::vector<Vec3>* f_ext) const {
  std::fill(f_ext->begin(), f_ext->end(), Vec3::Zero());
  if (!contact_this_frame_ || frame_samples_ == 0) return 0;
  // the frame's mean device force, reacted on the material point P_s: -F spread over the cell nodes of the
  // contact triangle's vertices by barycentric and trilinear weights (a sphere tool: over its contact patch)
  const Vec3 f_obj = object_force(-force_sum_N_ / static_cast<double>(frame_samples_));
  const PointWeights w = force_weights(contact_);
  for (int i = 0; i < w.count; ++i) (*f_ext)[w.node[i]] += w.weight[i] * f_obj;
  int loaded = 0;
  for (const Vec3& f : *f_ext) loaded += f.squaredNorm() > 0.0 ? 1 : 0;
  return loaded;
}

void FrameStage::fill_contact_model(LocalModel* m) {
  m->has_contact_model = false;
  if (!lattice_ || latest_.contact == ContactState::kFree || latest_.contact_tri < 0) return;
  const PointWeights w = force_weights(latest_);
  if (w.count == 0) return;
  Mat3 c;
  if (!compliance_.compute(*lattice_, w, false, &c)) return;
  Vec3 p = Vec3::Zero(), v = Vec3::Zero();
  const auto& tri = model_.rest.triangles[static_cast<std::size_t>(latest_.contact_tri)];
  for (int k = 0; k < 3; ++k) p += latest_.contact_bary[k] * vertices_m_[tri[k]];
  for (int i = 0; i < w.count; ++i) v += w.weight[i] * lattice_->v_m_per_s[w.node[i]];
  m->has_contact_model = true;
  m->contact_p0_m = p;
  m->contact_v0_m_per_s = v;
  m->contact_f0_N = frame_force_obj_N_;
  m->compliance_m_per_N = c;
  m->model_radius_m = lattice_->cell_m;
  ++stats_.contact_models;
}

void FrameStage::publish_patch() {
  LocalModel& m = local_model_->write_buffer();
  // triangles near the tool and the proxy, with a margin for the deformation since rest
  // (a sphere tool reaches its radius beyond its centre)
  const double margin = std::max(2.0 * model_.leaf_cell_m, scene_.grab_radius_m) + stats_.max_displacement_m +
                        (scene_.device.sphere_tool ? scene_.device.tool_radius_m : 0.0);
  const Vec3 lo = latest_.tool_pos_m.cwiseMin(latest_.proxy_pos_m) - Vec3::Constant(margin);
  const Vec3 hi = latest_.tool_pos_m.cwiseMax(latest_.proxy_pos_m) + Vec3::Constant(margin);
  if (cut_) {
    // the whole blade edge, whose triangles are not in the grid's leaf lists once split
    const Vec3 end = latest_.tool_pos_m + scene_.blade_length_m * latest_.blade_axis;
    cut_->triangles_in_box(vertices_m_, lo.cwiseMin(end - Vec3::Constant(margin)), hi.cwiseMax(end + Vec3::Constant(margin)),
                           &near_tris_);
  } else {
    model_.grid.triangles_near(lo, hi, &near_tris_);
  }
  // keep the held triangle first, then the nearest ones
  const Vec3 tool = latest_.tool_pos_m;
  const auto& tris = triangles();
  // cut mode: nearest to the blade edge, so the triangles it crosses are always kept
  const Vec3 edge = cut_ ? Vec3(scene_.blade_length_m * latest_.blade_axis) : Vec3::Zero();
  auto dist = [&](int32_t t) {
    const auto& tr = tris[static_cast<std::size_t>(t)];
    const Vec3 c = (vertices_m_[tr[0]] + vertices_m_[tr[1]] + vertices_m_[tr[2]]) / 3.0;
    const double u = edge.squaredNorm() > 0.0 ? std::clamp((c - tool).dot(edge) / edge.squaredNorm(), 0.0, 1.0) : 0.0;
    return (c - tool - u * edge).squaredNorm();
  };
  const int32_t held = latest_.contact != ContactState::kFree ? latest_.contact_tri : -1;
  m.truncated = near_tris_.size() > static_cast<std::size_t>(LocalModel::kMaxTriangles);
  if (m.truncated) {
    std::nth_element(near_tris_.begin(), near_tris_.begin() + LocalModel::kMaxTriangles - 1, near_tris_.end(),
                     [&](int32_t a, int32_t b) { return dist(a) < dist(b); });
    near_tris_.resize(LocalModel::kMaxTriangles - 1);
  }
  int n = 0;
  auto put = [&](int32_t t) {
    const auto& tr = tris[static_cast<std::size_t>(t)];
    m.tri_ids[n] = t;
    m.tri_m[n] = {vertices_m_[tr[0]], vertices_m_[tr[1]], vertices_m_[tr[2]]};
    m.normal[n] = {normals_[tr[0]], normals_[tr[1]], normals_[tr[2]]};
    ++n;
  };
  if (held >= 0) put(held);
  for (int32_t t : near_tris_)
    if (t != held && n < LocalModel::kMaxTriangles) put(t);
  m.num_triangles = n;
  m.frame = stats_.frames;
  m.t_s = t_s_;
  fill_contact_model(&m);
  local_model_->publish();
}

void FrameStage::render(int64_t index, bool block) {
  if (!renderer_ || !writer_) return;
  const auto t0 = std::chrono::steady_clock::now();
  uint8_t* buf = writer_->acquire(block);
  if (!buf) {
    ++stats_.frames_dropped;
    return;
  }
  FrameView view{};
  view.vertices_m = &vertices_m_;
  view.triangles = &triangles();
  view.normals = &normals_;
  view.tool_pos_m = latest_.tool_pos_m;
  view.tool_radius_m = scene_.device.tool_radius_m;
  // a sphere tool is drawn where it rests on the surface (its centre, the proxy); the spring goes to the device
  view.tool_at_proxy = scene_.device.sphere_tool;
  view.in_contact = latest_.contact != ContactState::kFree;
  view.show_proxy = view.in_contact && latest_.contact != ContactState::kCut;
  view.proxy_pos_m = latest_.proxy_pos_m;
  // cut mode moves the whole object and changes its topology: drawn in full
  if (!cut_) {
    view.moving_vertices = &deformer_.vertex_ids();
    view.layer_epoch = layer_epoch_;
  }
  if (cut_) {
    view.show_blade = true;
    view.blade_tip_m = latest_.tool_pos_m;
    view.blade_end_m = latest_.tool_pos_m + scene_.blade_length_m * latest_.blade_axis;
  }
  renderer_->draw(view, buf);
  stats_.frames_layered += renderer_->last_draw_layered() ? 1 : 0;
  // the video gets its own copy: its frame index is the scene's, so a skipped frame holds the last one shown
  if (video_) video_->submit(index, buf, block);
  if (live_) live_->offer_frame(index, buf);
  // files are numbered in the order written, so a realtime run's skipped frames leave no gap in the sequence;
  // written_frames says which scene frame each file shows
  writer_->submit(static_cast<int>(stats_.frames_rendered), buf);
  stats_.written_frames.push_back(index);
  ++stats_.frames_rendered;
  stats_.render_ms.push_back(ms_since(t0));
}

void FrameStage::frame(int64_t index, double t_s, bool block_on_writer) {
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpu_clock_.now_ms();
  frame_opts_ = budget_ ? &budget_->begin_frame() : nullptr;
  t_s_ = t_s;
  contact_this_frame_ = false;
  force_sum_N_.setZero();
  frame_samples_ = 0;
  drain();
  const bool cutting = cut_ && cut_frame();
  if (!lattice_ && contact_this_frame_) {
    // a sphere's centre is outside the surface: the region is built around the surface point under it
    Vec3 at = contact_.proxy_pos_m;
    if (scene_.device.sphere_tool) {
      const auto& tri = model_.rest.triangles[static_cast<std::size_t>(contact_.contact_tri)];
      at.setZero();
      for (int c = 0; c < 3; ++c) at += contact_.contact_bary[c] * vertices_m_[tri[c]];
    }
    build_lattice_at(at);
  }
  frame_force_obj_N_ = contact_this_frame_ && frame_samples_ > 0 ? object_force(-force_sum_N_ / static_cast<double>(frame_samples_))
                                                                  : Vec3::Zero();
  bool moved = false;
  if (lattice_) {
    follow_contact();
    if (const int nodes = apply_contact_force(&f_ext_N_); nodes > 0) stats_.force_nodes = nodes;
    moved = step_lattice_frame();
    if (moved && cut_) apply_floor(&*lattice_, floor_z_m_);
  }
  if (moved) {
    for (std::size_t i = 0; i < lattice_->num_nodes(); ++i)
      stats_.max_displacement_m = std::max(stats_.max_displacement_m, (lattice_->x_m[i] - lattice_->rest_m[i]).norm());
    if (cut_) cut_->deform(*lattice_, &vertices_m_);
    else deformer_.deform(*lattice_, model_.bindings, model_.rest.vertices_m, &vertices_m_);
  }
  // normals for the servo's inside test and for shading: only those of the region's vertices and their
  // neighbours can change, except in cut mode (whole-object lattice, changing topology)
  if (normals_.empty() || (cut_ && moved)) compute_vertex_normals(vertices_m_, triangles(), &normals_);
  else if (moved || region_changed_) update_vertex_normals(vertices_m_, triangles(), model_.adjacency, normal_ids_, &normals_);
  region_changed_ = false;
  publish_patch();
  stats_.sim_ms.push_back(ms_since(t0));
  stats_.sim_cpu_ms.push_back(cpu_clock_.now_ms() - c0);
  if (budget_) budget_->end_frame();
  if (cutting) stats_.cutting_ms.push_back(stats_.sim_ms.back());
  else if (stats_.frames_cutting > 0) stats_.after_cut_ms.push_back(stats_.sim_ms.back());
  ++stats_.frames;
  const std::size_t rendered = stats_.render_ms.size();
  render(index, block_on_writer);
  if (live_)
    live_->end_frame(index, t_s, stats_.sim_ms.back() + (stats_.render_ms.size() > rendered ? stats_.render_ms.back() : 0.0),
                     stats_.frames, writer_ ? writer_->frames_written() : 0, stats_.frames_dropped);
}

std::string FrameStage::state_hash() const {
  StateHash h;
  if (lattice_) {
    h.add(lattice_->x_m);
    h.add(lattice_->v_m_per_s);
  }
  h.add(vertices_m_);
  return h.hex();
}

}  // namespace palpate
