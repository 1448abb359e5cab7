#pragma once
// Interpolating quintic spline of D-dimensional points over time, C⁴: position, velocity,
// acceleration, jerk and snap are continuous, so a FlightTrajectory built on it has continuous
// body rates (its bank rate uses the jerk). Used for waypoint paths; ends are "natural" (zero
// jerk and snap) or periodic (closed paths, first point = last point).
//
// Each segment is the quintic Hermite polynomial fixed by (y, y', y'') at both ends; the knot
// velocities and accelerations are the unknowns, found from continuity of jerk and snap at the
// knots plus the end conditions (a dense 2(n+1) system: meant for up to a few hundred points).
// With τ = t − t_i, h = t_{i+1} − t_i, Δ = y_{i+1} − y_i:
//   jerk(τ=0) = (60Δ − 36 v0 h − 24 v1 h − 9 a0 h² + 3 a1 h²)/h³
//   jerk(τ=h) = (60Δ − 24 v0 h − 36 v1 h − 3 a0 h² + 9 a1 h²)/h³
//   snap(τ=0) = (−360Δ + 192 v0 h + 168 v1 h + 36 a0 h² − 24 a1 h²)/h⁴
//   snap(τ=h) = (360Δ − 168 v0 h − 192 v1 h − 24 a0 h² + 36 a1 h²)/h⁴

#include <Eigen/Core>
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "cvslam/scenario/cubic_spline.h"

namespace cvslam::sim {

template <int D>
class QuinticSpline {
 public:
  using Vec = Eigen::Matrix<double, D, 1>;

  QuinticSpline() = default;
  /// `times` strictly increasing, same length as `points` (≥ 2).
  QuinticSpline(std::vector<double> times, std::vector<Vec> points, bool periodic)
      : t_(std::move(times)), y_(std::move(points)), periodic_(periodic) {
    const int n = static_cast<int>(t_.size()) - 1;  // segments
    const int knots = periodic_ ? n : n + 1;        // knots with their own unknowns
    const int m = 2 * knots;
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(m, m);
    Eigen::MatrixXd b = Eigen::MatrixXd::Zero(m, D);
    const auto unknown = [&](int knot) { return 2 * (periodic_ ? knot % n : knot); };
    // Coefficients of (const·Δ, v0, a0, v1, a1) for jerk/snap at segment start/end.
    struct Row {
      double delta, v0, a0, v1, a1;
    };
    const auto rows = [](double h) {
      const double h2 = h * h, h3 = h2 * h, h4 = h3 * h;
      return std::array<Row, 4>{
          Row{60 / h3, -36 / h2, -9 / h, -24 / h2, 3 / h},          // jerk start
          Row{60 / h3, -24 / h2, -3 / h, -36 / h2, 9 / h},          // jerk end
          Row{-360 / h4, 192 / h3, 36 / h2, 168 / h3, -24 / h2},    // snap start
          Row{360 / h4, -168 / h3, -24 / h2, -192 / h3, 36 / h2}};  // snap end
    };
    // Adds sign·(quantity of segment s) to equation `eq`.
    const auto add = [&](int eq, int s, int which, double sign) {
      const double h = t_[idx(s + 1)] - t_[idx(s)];
      const Row r = rows(h)[static_cast<std::size_t>(which)];
      const int i0 = unknown(s), i1 = unknown(s + 1);
      A(eq, i0) += sign * r.v0;
      A(eq, i0 + 1) += sign * r.a0;
      A(eq, i1) += sign * r.v1;
      A(eq, i1 + 1) += sign * r.a1;
      b.row(eq) -= sign * r.delta * (y_[idx(s + 1)] - y_[idx(s)]).transpose();
    };
    int eq = 0;
    for (int k = periodic_ ? 0 : 1; k < n; ++k) {
      const int before = (k + n - 1) % n;  // segment ending at knot k
      add(eq, before, 1, 1.0);             // jerk continuity
      add(eq, k, 0, -1.0);
      ++eq;
      add(eq, before, 3, 1.0);  // snap continuity
      add(eq, k, 2, -1.0);
      ++eq;
    }
    if (!periodic_) {  // natural ends: zero jerk and snap
      add(eq++, 0, 0, 1.0);
      add(eq++, 0, 2, 1.0);
      add(eq++, n - 1, 1, 1.0);
      add(eq++, n - 1, 3, 1.0);
    }
    const Eigen::MatrixXd x = A.partialPivLu().solve(b);
    v_.resize(t_.size());
    a_.resize(t_.size());
    for (int k = 0; k <= n; ++k) {
      v_[idx(k)] = x.row(unknown(k)).transpose();
      a_[idx(k)] = x.row(unknown(k) + 1).transpose();
    }
  }

  double startTime() const { return t_.front(); }
  double endTime() const { return t_.back(); }
  bool periodic() const { return periodic_; }

  SplineSample<D> sample(double t) const {
    if (periodic_) {
      const double period = t_.back() - t_.front();
      t = t_.front() + (t - t_.front()) - period * std::floor((t - t_.front()) / period);
    }
    auto it = std::upper_bound(t_.begin(), t_.end(), t);
    const int i =
        std::clamp(static_cast<int>(it - t_.begin()) - 1, 0, static_cast<int>(t_.size()) - 2);
    const double h = t_[idx(i + 1)] - t_[idx(i)];
    const Vec& y0 = y_[idx(i)];
    const Vec& v0 = v_[idx(i)];
    const Vec& a0 = a_[idx(i)];
    const Vec& v1 = v_[idx(i + 1)];
    const Vec& a1 = a_[idx(i + 1)];
    const Vec d = y_[idx(i + 1)] - y0;
    const double h2 = h * h, h3 = h2 * h, h4 = h3 * h, h5 = h4 * h;
    const Vec c3 = (10 * d - 6 * h * v0 - 4 * h * v1 - 1.5 * h2 * a0 + 0.5 * h2 * a1) / h3;
    const Vec c4 = (-15 * d + 8 * h * v0 + 7 * h * v1 + 1.5 * h2 * a0 - h2 * a1) / h4;
    const Vec c5 = (6 * d - 3 * h * v0 - 3 * h * v1 - 0.5 * h2 * a0 + 0.5 * h2 * a1) / h5;
    const double s = t - t_[idx(i)];
    SplineSample<D> out;
    out.value = y0 + s * (v0 + s * (0.5 * a0 + s * (c3 + s * (c4 + s * c5))));
    out.d1 = v0 + s * (a0 + s * (3 * c3 + s * (4 * c4 + s * 5 * c5)));
    out.d2 = a0 + s * (6 * c3 + s * (12 * c4 + s * 20 * c5));
    out.d3 = 6 * c3 + s * (24 * c4 + s * 60 * c5);
    return out;
  }

 private:
  static std::size_t idx(int i) { return static_cast<std::size_t>(i); }
  std::vector<double> t_;
  std::vector<Vec> y_, v_, a_;
  bool periodic_ = false;
};

}  // namespace cvslam::sim
