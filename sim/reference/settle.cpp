#include "sim/reference/settle.h"

#include "core/thread_cpu.h"

#include <algorithm>
#include <ctime>
#include <string>

#include "sim/solvers/static_solve.h"

namespace palpate {
std::vector<Vec3> net_static_forces_N(const Lattice& lat, const std::vector<Vec3>& f_ext_N) {
  std::vector<Vec3> f = spring_forces_N(lat, lat.x_m);
  for (std::size_t i = 0; i < f.size(); ++i) {
    f[i] += lat.mass_kg[i] * lat.gravity_m_per_s2;
    if (!f_ext_N.empty()) f[i] += f_ext_N[i];
  }
  return f;
}

Result<SettleReport> settle(Lattice* lat, const std::vector<Vec3>& f_ext_N, const SettleOptions& o) {
  const std::size_t n = lat->num_nodes();
  double load = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!f_ext_N.empty()) load = std::max(load, f_ext_N[i].norm());
    load = std::max(load, (lat->mass_kg[i] * lat->gravity_m_per_s2).norm());
  }
  // a load given by displaced fixed nodes: the largest spring force at the start
  if (!(load > 0.0))
    for (const Vec3& f : spring_forces_N(*lat, lat->x_m)) load = std::max(load, f.norm());
  SettleReport rep;
  if (!(load > 0.0)) return rep;  // nothing pushes: at rest already
  IntegratorWorkspace ws;
  std::vector<double> ms;
  for (int frame = 0; frame < o.max_frames; ++frame) {
    const double t0 = thread_cpu_ms();
    const StepReport s = step_lattice(lat, o.step, o.frame_s, f_ext_N, &ws);
    ms.push_back(thread_cpu_ms() - t0);
    rep.frames = frame + 1;
    rep.substeps += s.substeps;
    if (s.diverged)
      return make_error("settle: the lattice diverged at frame ", std::to_string(frame), " (", integrator_name(o.step.kind), ")");
    double moved = 0.0, speed = 0.0, imbalance = 0.0;
    const std::vector<Vec3> f = net_static_forces_N(*lat, f_ext_N);
    for (std::size_t i = 0; i < n; ++i) {
      if (lat->fixed[i]) continue;
      moved = std::max(moved, (lat->x_m[i] - lat->rest_m[i]).norm());
      speed = std::max(speed, lat->v_m_per_s[i].norm());
      Vec3 free_f = f[i];
      if (!lat->held_dof.empty())
        for (int a = 0; a < 3; ++a)
          if (lat->held_dof[3 * i + static_cast<std::size_t>(a)]) free_f[a] = 0.0;
      imbalance = std::max(imbalance, free_f.norm());
    }
    rep.residual_rel = imbalance / load;
    if (rep.residual_rel < o.rest_rel && speed * o.frame_s <= o.rest_rel * moved) break;
    if (frame + 1 == o.max_frames)
      return make_error("settle: not at rest after ", std::to_string(o.max_frames), " frames (force imbalance ",
                        std::to_string(rep.residual_rel), " of the load, ", integrator_name(o.step.kind), ")");
  }
  std::nth_element(ms.begin(), ms.begin() + static_cast<std::ptrdiff_t>(ms.size() / 2), ms.end());
  rep.ms_per_frame_p50 = ms[ms.size() / 2];
  return rep;
}

}  // namespace palpate
