#pragma once
/// Contact solved under the tool, frame by frame: where a tool's push goes on the lattice, found from the lattice's
/// own compliance instead of a pressure formula. The tool's tip is a rigid sphere (a sphere tool's, or a point tool's
/// tip of device.tool_radius_m); points of the object's surface near it carry pressure only where the surface,
/// deformed by that pressure, touches the sphere (frictionless, unilateral), and the pressures sum to the push the
/// hand feels (the frame's mean device force). With the lattice's stiffness K factored (ContactCompliance), the
/// surface points' compliance C = W^T K^-1 W is condensed and the contact is a small linear complementarity problem
/// (solved by active sets): the pressure's shape comes out of the lattice, Hertz's formula is only a check.
/// The surface the sphere meets is the object as it would stand without the last frame's contact load
/// (x - K^-1 f_prev), so the load a dimple already carries is not counted twice. Thread: the sim thread (allocates
/// when sizes grow).

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/types.h"
#include "sim/contact/contact_compliance.h"
#include "sim/contact/contact_load.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// The dense contact problem: gaps g (m), their approach per unit move of the sphere a (m), compliance C (m x m).
/// Finds pressures p >= 0 and the sphere's move delta with g - delta a + C p >= 0, p (g - delta a + C p) = 0 and
/// a^T p = force. Plain data out.
struct ContactLcpResult {
  Eigen::VectorXd p;      ///< each point's force (N, along its sphere normal)
  double delta_m = 0.0;   ///< how far the sphere moved along the push
  int active = 0;         ///< points carrying force
  int iterations = 0;     ///< active-set changes
};

/// Solves the problem above by active sets from the first point to touch; false when it does not settle in 4 m + 8
/// changes or no point faces the push (a_i > 0). C's diagonal gets `give` (m/N, >= 0) added: the contact's own
/// compliance, which keeps C_AA regular when points outnumber the lattice's freedom under them.
bool solve_contact_lcp(const Eigen::MatrixXd& c, const Eigen::VectorXd& g, const Eigen::VectorXd& a, double force_N,
                       double give_m_per_N, ContactLcpResult* out);

/// A point of the surface the solved contact samples: its triangle and barycentric point (rest mesh numbering).
struct ContactPoint {
  int32_t tri = -1;
  Vec3 bary = Vec3::Zero();
};

/// The points of triangles `tris` (deformed positions vertices_m) facing against `push` (unit) within reach_m of the
/// line through centre_m along it, on a barycentric grid of about spacing_m; at most max_points, the nearest to the
/// line first. Points behind the sphere of radius_m at centre_m (beyond its far side, against the push: a part of the
/// model overhanging the tool) are not what it meets, and are left out.
void contact_points(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles,
                    const std::vector<int32_t>& tris, const Vec3& centre_m, const Vec3& push, double radius_m,
                    double reach_m, double spacing_m, int max_points, std::vector<ContactPoint>* out);

/// What the last solve came to. Plain data.
struct SolvedContactReport {
  int points = 0;              ///< surface points sampled
  int active = 0;              ///< points carrying force
  double contact_radius_m = 0; ///< the farthest loaded point from the push's line through the sphere's centre
  double delta_m = 0.0;        ///< the sphere's move along the push that makes the surface carry the force
};

/// The frame-by-frame solved load: keeps the last load (for the unloaded surface) and how far the contact reached.
/// Not copyable. Thread: the sim thread.
class SolvedContactLoad {
 public:
  /// Most surface points per solve: the condensation costs a forward solve each and the active-set solves m^3.
  static constexpr int kMaxPoints = 48;

  /// The weights (summing to 1) of the push f_obj_N on the lattice's nodes, found by the contact of the sphere
  /// (centre_m, radius_m) with the surface near it: tris are candidate triangles (e.g. the servo's patch),
  /// vertices_m the deformed mesh, compliance a factor of lat's stiffness (ready()). False, *w untouched, when there
  /// is no factor, no push, no surface point facing it, or the problem does not settle: the caller loads by formula.
  bool weights(const Lattice& lat, const RestObject& rest, const std::vector<Vec3>& vertices_m,
               const std::vector<int32_t>& tris, const Vec3& centre_m, double radius_m, const Vec3& f_obj_N,
               ContactCompliance* compliance, PointWeights* w);

  /// Forgets the last load (a new lattice, or the contact released).
  void reset();

  const SolvedContactReport& report() const { return report_; }

 private:
  double reach_m_ = 0.0;                // lateral reach of the next solve's points (0: start from the radius)
  std::vector<Vec3> last_load_N_;       // the last solve's load on the lattice's nodes (n)
  std::vector<Vec3> unload_m_;          // K^-1 of it
  std::vector<ContactPoint> points_;
  std::vector<PointWeights> point_w_;
  std::vector<Vec3> dirs_;
  Eigen::MatrixXd c_;
  Eigen::VectorXd g_, a_;
  ContactLcpResult lcp_;
  SolvedContactReport report_;
};

}  // namespace palpate
