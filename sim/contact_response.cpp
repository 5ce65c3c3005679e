#include "sim/contact_response.h"

namespace palpate {

bool contact_response(const Lattice& lat, const PointWeights& w, const Vec3& point_m, const Vec3& f_N,
                      ContactCompliance* compliance, ContactResponse* out) {
  // the compliance's condensation knows no hanging nodes: a refined lattice gives the servo no contact model
  if (w.count == 0 || !lat.hanging.empty()) return false;
  Mat3 c;
  if (!compliance->compute(lat, w, false, &c)) return false;
  Vec3 v = Vec3::Zero();
  for (int i = 0; i < w.count; ++i) v += w.weight[i] * lat.v_m_per_s[w.node[i]];
  out->p0_m = point_m;
  out->v0_m_per_s = v;
  out->f0_N = f_N;
  out->compliance_m_per_N = c;
  out->radius_m = lat.cell_m;
  return true;
}

}  // namespace palpate
