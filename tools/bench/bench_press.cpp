#include "tools/bench/bench_press.h"

#include <algorithm>
#include <cmath>

#include "core/scene.h"
#include "sim/lattice/lattice.h"
#include "sim/contact/sphere_contact.h"
#include "runtime/session/model.h"

namespace palpate {

Result<std::vector<PressRow>> run_solved_press(const std::string& scene_path, double young_modulus_Pa,
                                               const std::vector<int>& levels) {
  constexpr int kIncrements = 8;
  auto loaded = load_scene(scene_path);
  if (!loaded) return loaded.error();
  std::vector<PressRow> rows;
  for (int level : levels) {
    Scene s = loaded.value();
    if (young_modulus_Pa > 0.0) s.lattice.material.young_modulus_Pa = young_modulus_Pa;
    s.lattice.level = level;
    s.lattice.radius_cells = level <= 4 ? 3 : 3 << (level - 4);
    s.grid_levels = std::max({5, level, s.grid_levels});
    auto where = [&](const std::string& what) { return "solved press of '" + scene_path + "' at level " + std::to_string(level) + ": " + what; };
    auto model = load_model(s);
    if (!model) return make_error(where(model.error().message));
    const Model& m = model.value();
    Vec3 hold = s.trajectory.front().pos_m;
    for (const Keyframe& k : s.trajectory)
      if (k.pos_m.z() < hold.z()) hold = k.pos_m;
    // the top of the object under the hold point: the highest rest vertex within a tool radius of its vertical
    const double radius = s.device.tool_radius_m;
    double top = -INFINITY;
    for (const Vec3& v : m.rest.vertices_m)
      if (std::hypot(v.x() - hold.x(), v.y() - hold.y()) < std::max(radius, 2.0 * m.leaf_cell_m)) top = std::max(top, v.z());
    if (!std::isfinite(top)) return make_error(where("no surface above the trajectory's lowest key"));
    const Vec3 at(hold.x(), hold.y(), top - 1e-6);
    auto built = build_lattice(m.grid, s.lattice, region_cells(m.grid, level, m.grid.cell_of(at, level), s.lattice.radius_cells));
    if (!built) return make_error(where(built.error().message));
    Lattice lat = std::move(built).value();
    PressRow row;
    row.level = level;
    row.radius_cells = s.lattice.radius_cells;
    row.nodes = lat.num_nodes();
    row.samples_per_edge = std::max(1, static_cast<int>(std::ceil(2.0 * lat.cell_m / radius - 1e-9)));
    const std::vector<SurfaceSample> samples = lattice_surface_samples(lat, row.samples_per_edge);
    // at rest the hand's spring pulls the device toward the trajectory and the coupling pulls it to the proxy: in
    // series, one spring from the trajectory point to the sphere's centre
    SphereContactOptions so;
    so.penalty_Pa_per_m = contact_penalty_Pa_per_m(s.lattice.material.young_modulus_Pa, lat.cell_m);
    so.coupling_N_per_m = 1.0 / (1.0 / s.device.coupling_N_per_m + 1.0 / s.hand.stiffness_N_per_m);
    // the soft lattice squashed under a small sphere: its energy stops falling at round-off before the step does
    so.residual_tol_N = 1e-5;
    const Vec3 start(at.x(), at.y(), top + radius);
    Vec3 centre = start;
    SphereContactResult r;
    for (int i = 1; i <= kIncrements; ++i) {
      so.device_m = start + (hold - start) * (static_cast<double>(i) / kIncrements);
      auto solved = solve_sphere_contact(&lat, {}, samples, centre, radius, so);
      if (!solved) {
        row.failure = "increment " + std::to_string(i) + " of " + std::to_string(kIncrements) + ": " + solved.error().message;
        break;
      }
      r = solved.value();
      centre = r.centre_m;
      row.iterations += r.iterations;
    }
    if (!row.failure.empty()) {
      rows.push_back(row);
      continue;
    }
    row.force_N = r.force_N.z();
    row.depth_m = top - (centre.z() - radius);
    row.active = r.active;
    row.max_penetration_m = r.max_penetration_m;
    rows.push_back(row);
  }
  return rows;
}

}  // namespace palpate
