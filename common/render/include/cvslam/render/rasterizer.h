#pragma once
// Software triangle rasteriser with an inverse-depth z-buffer (one pinhole camera).
//
// Pixel (i, j) is sampled at its centre, which is the image point u = i, v = j (OpenCV
// convention, the same as StereoCamera::project). For a planar triangle the inverse depth
// 1/z_C is an affine function of (u, v): w = P·[u v 1]. The rasteriser computes P from the
// 3-D triangle (not from clipped screen vertices), stores it per triangle, and keeps per pixel
// the largest w (nearest surface) and the id of its triangle. Anything shaded later is then
// perspective-correct, and the exact 3-D point of any pixel, even at sub-pixel positions, is
// p_C = [(u − cx)/fx, (v − cy)/fy, 1] / w.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <vector>

namespace cvslam::render {

struct PinholeIntrinsics {
  double fx = 1.0, fy = 1.0, cx = 0.0, cy = 0.0;
  int width = 0, height = 0;
};

class Rasterizer {
 public:
  /// Surfaces nearer than `near` are clipped; farther than `far` are not drawn.
  Rasterizer(const PinholeIntrinsics& k, double near, double far);

  /// Empties the buffers and the triangle list (no allocation after the first frame).
  void clear();
  /// Draws a triangle given in the camera frame. Returns its id (index into planes()), or −1
  /// when it cannot cover any pixel (behind the camera, edge-on or outside the image).
  int draw(const Eigen::Vector3d& a_C, const Eigen::Vector3d& b_C, const Eigen::Vector3d& c_C);

  const PinholeIntrinsics& intrinsics() const { return k_; }
  /// Per pixel: inverse depth 1/z_C of the nearest surface (1/far where there is none).
  const cv::Mat1f& inverseDepth() const { return inv_depth_; }
  /// Per pixel: id of the nearest triangle, −1 where there is none.
  const cv::Mat1i& triangleIds() const { return ids_; }
  /// Per triangle id: P with 1/z_C = P·[u v 1].
  const std::vector<Eigen::Vector3d>& planes() const { return planes_; }

 private:
  void fillConvexPolygon(const Eigen::Vector2d* q, int n, const Eigen::Vector3d& plane, int id);

  PinholeIntrinsics k_;
  double near_, far_;
  cv::Mat1f inv_depth_;
  cv::Mat1i ids_;
  std::vector<Eigen::Vector3d> planes_;
};

}  // namespace cvslam::render
