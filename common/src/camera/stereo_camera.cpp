#include "cvslam/camera/stereo_camera.h"

#include <Eigen/LU>  // determinant()

#include "cvslam/geometry/euler.h"
#include "cvslam/io/config_node.h"

namespace cvslam {

Status StereoCameraOptions::load(const ConfigNode& node) {
  node.get("fx", fx);
  node.get("fy", fy);
  node.get("cx", cx);
  node.get("cy", cy);
  node.get("width", width);
  node.get("height", height);
  node.get("baseline", baseline);
  node.get("R_BtoC", R_BtoC);
  node.get("p_CinB", p_CinB);
  node.get("min_depth", min_depth);
  node.check(fx > 0 && fy > 0, "fx", "focal lengths must be > 0");
  node.check(width > 0 && height > 0, "width", "image size must be > 0");
  node.check(baseline > 0, "baseline", "must be > 0");
  node.check(min_depth > 0, "min_depth", "must be > 0");
  node.check((R_BtoC * R_BtoC.transpose()).isIdentity(1e-6) && R_BtoC.determinant() > 0, "R_BtoC",
             "must be a rotation matrix");
  return node.status();
}

Eigen::Vector3d StereoCamera::landmarkInCamera(const Eigen::Vector3d& p_BinN,
                                               const Eigen::Vector3d& euler,
                                               const Eigen::Vector3d& p_LinN) const {
  return o_.R_BtoC * (rotationNavToBody(euler) * (p_LinN - p_BinN) - o_.p_CinB);
}

Eigen::Vector4d StereoCamera::project(const Eigen::Vector3d& p_LinC) const {
  const double inv_z = 1.0 / p_LinC.z();
  const double u_l = o_.fx * p_LinC.x() * inv_z + o_.cx;
  const double v = o_.fy * p_LinC.y() * inv_z + o_.cy;
  const double u_r = o_.fx * (p_LinC.x() - o_.baseline) * inv_z + o_.cx;
  return {u_l, v, u_r, v};
}

bool StereoCamera::isVisible(const Eigen::Vector3d& p_LinC) const {
  if (!(p_LinC.z() >= o_.min_depth)) return false;
  const Eigen::Vector4d z = project(p_LinC);
  const auto inside = [&](double u, double v) {
    return u >= 0.0 && u < o_.width && v >= 0.0 && v < o_.height;
  };
  return inside(z(0), z(1)) && inside(z(2), z(3));
}

}  // namespace cvslam
