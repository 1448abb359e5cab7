#pragma once
// Scenes shared by the renderer tests and benchmark: worlds, cameras and poses.

#include <Eigen/Core>

#include <memory>
#include <utility>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/render/world.h"

namespace cvslam::test {

inline std::shared_ptr<const render::World> makeWorld(render::WorldKind kind,
                                              render::TextureVariant variant = render::TextureVariant::kHigh,
                                              uint64_t seed = 1) {
  render::WorldOptions o;
  o.kind = kind;
  o.seed = seed;
  o.texture.seed = seed;
  o.texture.variant = variant;
  auto world = render::World::create(o);
  return world.ok() ? *world : nullptr;
}

/// EuRoC VI-sensor-like rectified pair (752×480, f ≈ 458 px, 11 cm baseline) looking along
/// the body x axis (forward): x_C = y_B (right), y_C = z_B (down), z_C = x_B.
inline StereoCamera euroCCamera(int width = 752, int height = 480) {
  StereoCameraOptions o;
  o.width = width;
  o.height = height;
  o.fx = o.fy = 458.0 * width / 752.0;
  o.cx = 0.5 * width;
  o.cy = 0.5 * height;
  o.baseline = 0.11;
  o.R_BtoC << 0, 1, 0, 0, 0, 1, 1, 0, 0;
  return StereoCamera(o);
}

/// 10 m above the aerial terrain near take-off, slightly banked (thesis Table 5.6 geometry).
inline std::pair<Eigen::Vector3d, Eigen::Vector3d> aerialPose() {
  return {Eigen::Vector3d(3.0, 7.0, -10.0), Eigen::Vector3d(0.05, -0.03, 0.4)};
}

/// Inside the default hall, 3 m above the floor, looking east (towards shelves) and down.
inline std::pair<Eigen::Vector3d, Eigen::Vector3d> hallPose() {
  return {Eigen::Vector3d(5.0, -4.0, -1.0), Eigen::Vector3d(0.02, -0.2, 1.3)};
}

}  // namespace cvslam::test
