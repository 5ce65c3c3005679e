#include "sim/contact/contact_response.h"

namespace palpate {
namespace {

ContactResponse response(const Lattice& lat, const PointWeights& w, const Vec3& point_m, const Vec3& f_N, const Mat3& c) {
  ContactResponse r;
  Vec3 v = Vec3::Zero();
  for (int i = 0; i < w.count; ++i) v += w.weight[i] * lat.v_m_per_s[w.node[i]];
  r.p0_m = point_m;
  r.v0_m_per_s = v;
  r.f0_N = f_N;
  r.compliance_m_per_N = c;
  r.radius_m = lat.cell_m;
  return r;
}

}  // namespace

bool contact_response(const Lattice& lat, const PointWeights& w, const Vec3& point_m, const Vec3& f_N,
                      ContactCompliance* compliance, ContactResponse* out) {
  // the compliance's condensation knows no hanging nodes: a refined lattice gives the servo no contact model
  if (w.count == 0 || !lat.hanging.empty()) return false;
  Mat3 c;
  if (!compliance->compute(lat, w, false, &c)) return false;
  *out = response(lat, w, point_m, f_N, c);
  return true;
}

bool contact_response_with(const Lattice& lat, const PointWeights& w, const Vec3& point_m, const Vec3& f_N,
                           const Mat3& c_m_per_N, ContactResponse* out) {
  if (w.count == 0) return false;
  *out = response(lat, w, point_m, f_N, c_m_per_N);
  return true;
}

}  // namespace palpate
