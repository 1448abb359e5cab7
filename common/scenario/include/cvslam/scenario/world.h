#pragma once
// Simulated world for feature-level simulation (thesis §5.9): point landmarks scattered over
// a terrain, each with a unique true id (used as the feature index, docs/conventions.md).
//
// Terrain: a seeded smooth heightfield — the sum of four plane waves with random directions
// and phases, wavelengths λ, λ/2, λ/3, λ/5 and amplitudes A·(0.5, 0.25, 0.15, 0.1):
//   ground z_N(x, y) = ground_z − h(x, y)     (NED: up is −z; relief A = 0 gives flat ground)
// Landmarks: uniformly distributed over the region at `landmark_density` per m² (count =
// round(density · area)), each raised above the ground by U(0, landmark_height_jitter)
// (rocks, bushes). Ids are 0 … N−1 and landmarks()[id].id == id. A uniform grid indexes them
// for fast visibility queries.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "cvslam/core/random.h"
#include "cvslam/core/status.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::sim {

struct WorldOptions {
  double ground_z = 0.0;          ///< NED z of the mean ground [m] (flying at z = −10 is 10 m up)
  double relief_amplitude = 1.0;  ///< A: total relief amplitude [m] (0: flat)
  double relief_wavelength = 60.0;      ///< λ: longest terrain wavelength [m]
  double landmark_density = 0.5;        ///< landmarks per m² of ground
  double landmark_height_jitter = 0.5;  ///< landmarks sit up to this high above ground [m]
  double margin = 40.0;  ///< region = bounding box of the trajectories (x, y) + this [m]

  Status load(const ConfigNode& node);
};

struct Landmark {
  uint32_t id = 0;
  Eigen::Vector3d p_LinN = Eigen::Vector3d::Zero();  ///< true position, NED [m]
};

class Terrain {
 public:
  Terrain() = default;
  Terrain(const WorldOptions& options, Rng& rng);
  /// Ground height as NED z at (x, y) [m].
  double groundZ(double x, double y) const;

 private:
  double ground_z_ = 0.0;
  Eigen::Matrix<double, 4, 2> k_ = Eigen::Matrix<double, 4, 2>::Zero();  // wave vectors
  Eigen::Vector4d amplitude_ = Eigen::Vector4d::Zero();
  Eigen::Vector4d phase_ = Eigen::Vector4d::Zero();
};

class World {
 public:
  /// Landmarks over `region` (x, y in NED, margin NOT added here). Fails when the count would
  /// exceed 20 million.
  static Expected<World> generate(const WorldOptions& options, const Eigen::AlignedBox2d& region,
                                  uint64_t seed);

  const std::vector<Landmark>& landmarks() const { return landmarks_; }
  const Terrain& terrain() const { return terrain_; }
  const Eigen::AlignedBox2d& region() const { return region_; }
  /// Smallest and largest landmark z (NED) [m].
  double minZ() const { return min_z_; }
  double maxZ() const { return max_z_; }

  /// Calls f(landmark) for every landmark whose (x, y) may lie in the box (grid cells that
  /// touch it; callers do their own exact test).
  template <typename F>
  void forEachNear(const Eigen::AlignedBox2d& box, F&& f) const {
    if (landmarks_.empty()) return;
    const int i0 = cellX(box.min().x()), i1 = cellX(box.max().x());
    const int j0 = cellY(box.min().y()), j1 = cellY(box.max().y());
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const std::size_t c = static_cast<std::size_t>(j * nx_ + i);
        for (uint32_t k = cell_start_[c]; k < cell_start_[c + 1]; ++k) f(landmarks_[k]);
      }
    }
  }

 private:
  int cellX(double x) const;
  int cellY(double y) const;

  std::vector<Landmark> landmarks_;  // sorted by grid cell; id == index
  std::vector<uint32_t> cell_start_;
  Terrain terrain_;
  Eigen::AlignedBox2d region_;
  double cell_ = 1.0;
  int nx_ = 1, ny_ = 1;
  double min_z_ = 0.0, max_z_ = 0.0;
};

}  // namespace cvslam::sim
