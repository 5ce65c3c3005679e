#pragma once
/// Basic numeric types shared by every module (SI units, world frame unless a name says otherwise).

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace palpate {

using Vec3 = Eigen::Vector3d;     ///< 3-vector in metres (or N, m/s as named)
using Vec3f = Eigen::Vector3f;    ///< single-precision 3-vector for rendering
using Mat3 = Eigen::Matrix3d;     ///< 3x3 matrix
using Quat = Eigen::Quaterniond;  ///< unit quaternion orientation

}  // namespace palpate
