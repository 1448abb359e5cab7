#include "cvslam/render/rasterizer.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace cvslam::render {

Rasterizer::Rasterizer(const PinholeIntrinsics& k, double near, double far)
    : k_(k), near_(near), far_(far), inv_depth_(k.height, k.width), ids_(k.height, k.width) {
  clear();
}

void Rasterizer::clear() {
  inv_depth_.setTo(static_cast<float>(1.0 / far_));
  ids_.setTo(-1);
  planes_.clear();
}

int Rasterizer::draw(const Eigen::Vector3d& a_C, const Eigen::Vector3d& b_C,
                     const Eigen::Vector3d& c_C) {
  if (a_C.z() < near_ && b_C.z() < near_ && c_C.z() < near_) return -1;
  if (a_C.z() > far_ && b_C.z() > far_ && c_C.z() > far_) return -1;
  // Plane n·p = d through the triangle; 1/z on the ray p = z·[(u−cx)/fx, (v−cy)/fy, 1] is
  // n·ray(u, v) / d, affine in (u, v).
  const Eigen::Vector3d n = (b_C - a_C).cross(c_C - a_C);
  const double d = n.dot(a_C);
  if (std::abs(d) < 1e-12 * n.norm() || n.squaredNorm() == 0.0) return -1;  // edge-on
  const Eigen::Vector3d plane(n.x() / (k_.fx * d), n.y() / (k_.fy * d),
                              (n.z() - n.x() * k_.cx / k_.fx - n.y() * k_.cy / k_.fy) / d);

  // Clip against the near plane (Sutherland–Hodgman, one plane): at most 4 vertices.
  const Eigen::Vector3d in[3] = {a_C, b_C, c_C};
  Eigen::Vector2d q[4];
  int m = 0;
  auto project = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d(k_.fx * p.x() / p.z() + k_.cx, k_.fy * p.y() / p.z() + k_.cy);
  };
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d& p = in[i];
    const Eigen::Vector3d& r = in[(i + 1) % 3];
    const bool p_in = p.z() >= near_, r_in = r.z() >= near_;
    if (p_in) q[m++] = project(p);
    if (p_in != r_in) {
      const double t = (near_ - p.z()) / (r.z() - p.z());
      q[m++] = project(p + t * (r - p));
    }
  }
  if (m < 3) return -1;
  double u_min = q[0].x(), u_max = u_min, v_min = q[0].y(), v_max = v_min;
  for (int i = 1; i < m; ++i) {
    u_min = std::min(u_min, q[i].x());
    u_max = std::max(u_max, q[i].x());
    v_min = std::min(v_min, q[i].y());
    v_max = std::max(v_max, q[i].y());
  }
  if (u_max < -0.5 || v_max < -0.5 || u_min > k_.width - 0.5 || v_min > k_.height - 0.5) return -1;
  const int id = static_cast<int>(planes_.size());
  planes_.push_back(plane);
  fillConvexPolygon(q, m, plane, id);
  return id;
}

void Rasterizer::fillConvexPolygon(const Eigen::Vector2d* q, int n, const Eigen::Vector3d& plane,
                                   int id) {
  double area2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = q[i];
    const Eigen::Vector2d& r = q[(i + 1) % n];
    area2 += p.x() * r.y() - r.x() * p.y();
  }
  if (std::abs(area2) < 1e-12) return;
  const double sign = area2 > 0 ? 1.0 : -1.0;
  // Edge functions E(u, v) = a u + b v + c, ≥ 0 inside for every edge.
  double ea[4], eb[4], ec[4];
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = q[i];
    const Eigen::Vector2d& r = q[(i + 1) % n];
    ea[i] = -(r.y() - p.y()) * sign;
    eb[i] = (r.x() - p.x()) * sign;
    ec[i] = ((r.y() - p.y()) * p.x() - (r.x() - p.x()) * p.y()) * sign;
  }
  double v_min = q[0].y(), v_max = v_min, u_min = q[0].x(), u_max = u_min;
  for (int i = 1; i < n; ++i) {
    v_min = std::min(v_min, q[i].y());
    v_max = std::max(v_max, q[i].y());
    u_min = std::min(u_min, q[i].x());
    u_max = std::max(u_max, q[i].x());
  }
  // A small tolerance makes neighbouring triangles overlap by a hair instead of leaving
  // cracks; the z-test resolves the overlap.
  constexpr double kEps = 1e-7;
  const int j0 = std::max(0, static_cast<int>(std::ceil(v_min - kEps)));
  const int j1 = std::min(k_.height - 1, static_cast<int>(std::floor(v_max + kEps)));
  const int i_lo = std::max(0, static_cast<int>(std::ceil(u_min - kEps)));
  const int i_hi = std::min(k_.width - 1, static_cast<int>(std::floor(u_max + kEps)));
  for (int j = j0; j <= j1; ++j) {
    double lo = i_lo, hi = i_hi;
    bool empty = false;
    for (int e = 0; e < n; ++e) {
      const double rest = eb[e] * j + ec[e];
      if (ea[e] > 0) {
        lo = std::max(lo, std::ceil(-rest / ea[e] - kEps));
      } else if (ea[e] < 0) {
        hi = std::min(hi, std::floor(-rest / ea[e] + kEps));
      } else if (rest < -kEps) {
        empty = true;
      }
    }
    if (empty || lo > hi) continue;
    float* wrow = inv_depth_.ptr<float>(j);
    int* idrow = ids_.ptr<int>(j);
    const double w_row = plane.y() * j + plane.z();
    for (int i = static_cast<int>(lo); i <= static_cast<int>(hi); ++i) {
      const float w = static_cast<float>(plane.x() * i + w_row);
      if (w > wrow[i]) {
        wrow[i] = w;
        idrow[i] = id;
      }
    }
  }
}

}  // namespace cvslam::render
