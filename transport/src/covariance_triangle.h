#pragma once
// The 3×3 landmark covariance on the wire as its upper triangle xx xy xz yy yz zz
// (shared_landmarks2_t.lcm, map_t.lcm): one layout for every converter.
#include <Eigen/Core>
#include <vector>

namespace cvslam::transport {

constexpr int kTriangle[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};

inline std::vector<double> upperTriangle(const Eigen::Matrix3d& P) {
  std::vector<double> c(6);
  for (int k = 0; k < 6; ++k) c[static_cast<std::size_t>(k)] = P(kTriangle[k][0], kTriangle[k][1]);
  return c;
}

inline Eigen::Matrix3d fromUpperTriangle(const std::vector<double>& c) {
  Eigen::Matrix3d P;
  for (int k = 0; k < 6; ++k) {
    const double v = c[static_cast<std::size_t>(k)];
    P(kTriangle[k][0], kTriangle[k][1]) = v;
    P(kTriangle[k][1], kTriangle[k][0]) = v;
  }
  return P;
}

}  // namespace cvslam::transport
