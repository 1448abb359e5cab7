#pragma once
// Regular-grid terrain heights in N (NED): vertex (i, j) is at x = x0 + i·cell,
// y = y0 + j·cell, z = down(i, j). Each grid cell is two triangles split along the diagonal
// from (i, j) to (i+1, j+1); downAt() interpolates on those same triangles, so it is the exact
// surface the renderer draws.

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace cvslam::render {

class Heightfield {
 public:
  Heightfield() = default;
  /// `down` holds (nx+1)·(ny+1) vertex values, row j major: down[j·(nx+1) + i].
  Heightfield(double x0, double y0, double cell, int nx, int ny, std::vector<double> down)
      : x0_(x0), y0_(y0), cell_(cell), nx_(nx), ny_(ny), down_(std::move(down)) {
    const auto [lo, hi] = std::minmax_element(down_.begin(), down_.end());
    min_down_ = *lo;
    max_down_ = *hi;
  }

  double x0() const { return x0_; }
  double y0() const { return y0_; }
  double cell() const { return cell_; }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  double minDown() const { return min_down_; }
  double maxDown() const { return max_down_; }
  double vertexDown(int i, int j) const { return down_[j * (nx_ + 1) + i]; }
  Eigen::Vector3d vertex(int i, int j) const {
    return {x0_ + i * cell_, y0_ + j * cell_, vertexDown(i, j)};
  }
  bool contains(double x, double y) const {
    return x >= x0_ && y >= y0_ && x <= x0_ + nx_ * cell_ && y <= y0_ + ny_ * cell_;
  }

  /// Terrain z (down) under (x, y); clamped to the grid outside it.
  double downAt(double x, double y) const {
    const double gx = std::clamp((x - x0_) / cell_, 0.0, static_cast<double>(nx_));
    const double gy = std::clamp((y - y0_) / cell_, 0.0, static_cast<double>(ny_));
    const int i = std::min(static_cast<int>(gx), nx_ - 1);
    const int j = std::min(static_cast<int>(gy), ny_ - 1);
    const double fx = gx - i, fy = gy - j;
    const double z00 = vertexDown(i, j), z11 = vertexDown(i + 1, j + 1);
    // Lower triangle (fx ≥ fy): (i,j), (i+1,j), (i+1,j+1); upper: (i,j), (i+1,j+1), (i,j+1).
    if (fx >= fy)
      return z00 + fx * (vertexDown(i + 1, j) - z00) + fy * (z11 - vertexDown(i + 1, j));
    return z00 + fy * (vertexDown(i, j + 1) - z00) + fx * (z11 - vertexDown(i, j + 1));
  }

 private:
  double x0_ = 0.0, y0_ = 0.0, cell_ = 1.0;
  int nx_ = 0, ny_ = 0;
  std::vector<double> down_;
  double min_down_ = 0.0, max_down_ = 0.0;
};

}  // namespace cvslam::render
