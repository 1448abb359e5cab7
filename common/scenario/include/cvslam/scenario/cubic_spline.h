#pragma once
// Interpolating cubic spline of D-dimensional points over time, C² (continuous acceleration),
// with analytic first to third derivatives. End conditions: natural (zero second derivative
// at both ends) or periodic (closed paths: value, slope and curvature continuous across the
// seam; the first and last points must coincide).
//
// Segment i on [t_i, t_{i+1}], h = t_{i+1} − t_i, A = (t_{i+1} − t)/h, B = 1 − A, M = y'':
//   y = A y_i + B y_{i+1} + ((A³ − A) M_i + (B³ − B) M_{i+1}) h²/6.
// Outside the knots an open spline continues its end cubic; a periodic one wraps.
// The jerk (third derivative) is piecewise constant, so attitude laws that use it (the bank
// rate in FlightTrajectory) would step at the knots: waypoint paths use QuinticSpline instead.
// CubicSpline interpolates TUM trajectories (positions and quaternions, ω from q̇ is continuous).

#include <Eigen/Core>
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

namespace cvslam::sim {

template <int D>
struct SplineSample {
  using Vec = Eigen::Matrix<double, D, 1>;
  Vec value = Vec::Zero();
  Vec d1 = Vec::Zero();  ///< first derivative
  Vec d2 = Vec::Zero();  ///< second derivative
  Vec d3 = Vec::Zero();  ///< third derivative (piecewise constant)
};

template <int D>
class CubicSpline {
 public:
  using Vec = Eigen::Matrix<double, D, 1>;

  CubicSpline() = default;
  /// `times` strictly increasing, same length as `points`, at least 2 points. Periodic splines
  /// solve a dense system (meant for tens to hundreds of waypoints); natural ones are O(n).
  CubicSpline(std::vector<double> times, std::vector<Vec> points, bool periodic)
      : t_(std::move(times)), y_(std::move(points)), periodic_(periodic) {
    const int n = static_cast<int>(t_.size()) - 1;  // number of segments
    m_.assign(t_.size(), Vec::Zero());
    if (n < 2) return;  // one segment: straight line (M = 0)
    std::vector<double> h(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) h[idx(i)] = t_[idx(i + 1)] - t_[idx(i)];
    const auto rhs = [&](int i, int im1, int ip1, double h_prev, double h_next) {
      return Vec(6.0 *
                 ((y_[idx(ip1)] - y_[idx(i)]) / h_next - (y_[idx(i)] - y_[idx(im1)]) / h_prev));
    };
    if (periodic_) {
      // Unknowns M_0..M_{n−1}; M_n = M_0.
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
      Eigen::MatrixXd b(n, D);
      for (int i = 0; i < n; ++i) {
        const int im1 = (i + n - 1) % n;
        const double hp = h[idx(im1)], hn = h[idx(i)];
        A(i, im1) += hp;
        A(i, i) += 2.0 * (hp + hn);
        A(i, (i + 1) % n) += hn;
        b.row(i) = rhs(i, i == 0 ? n - 1 : i - 1, i + 1, hp, hn).transpose();
      }
      const Eigen::MatrixXd m = A.partialPivLu().solve(b);
      for (int i = 0; i < n; ++i) m_[idx(i)] = m.row(i).transpose();
      m_[idx(n)] = m_[0];
    } else {
      // Thomas algorithm for the interior M_1..M_{n−1}; M_0 = M_n = 0.
      std::vector<double> c(static_cast<std::size_t>(n), 0.0);
      std::vector<Vec> d(static_cast<std::size_t>(n), Vec::Zero());
      for (int i = 1; i < n; ++i) {
        const double a = h[idx(i - 1)], bdiag = 2.0 * (h[idx(i - 1)] + h[idx(i)]), cc = h[idx(i)];
        const double denom = bdiag - (i > 1 ? a * c[idx(i - 1)] : 0.0);
        c[idx(i)] = cc / denom;
        d[idx(i)] = (rhs(i, i - 1, i + 1, h[idx(i - 1)], h[idx(i)]) -
                     (i > 1 ? Vec(a * d[idx(i - 1)]) : Vec(Vec::Zero()))) /
                    denom;
      }
      m_[idx(n - 1)] = d[idx(n - 1)];
      for (int i = n - 2; i >= 1; --i) m_[idx(i)] = d[idx(i)] - c[idx(i)] * m_[idx(i + 1)];
    }
  }

  bool empty() const { return t_.size() < 2; }
  double startTime() const { return t_.front(); }
  double endTime() const { return t_.back(); }
  bool periodic() const { return periodic_; }

  SplineSample<D> sample(double t) const {
    if (periodic_) {
      const double period = t_.back() - t_.front();
      t = t_.front() + (t - t_.front()) - period * std::floor((t - t_.front()) / period);
    }
    auto it = std::upper_bound(t_.begin(), t_.end(), t);
    int i = static_cast<int>(it - t_.begin()) - 1;
    i = std::clamp(i, 0, static_cast<int>(t_.size()) - 2);
    const double h = t_[idx(i + 1)] - t_[idx(i)];
    const double a = (t_[idx(i + 1)] - t) / h, b = 1.0 - a;
    const Vec& mi = m_[idx(i)];
    const Vec& mj = m_[idx(i + 1)];
    SplineSample<D> s;
    s.value = a * y_[idx(i)] + b * y_[idx(i + 1)] +
              ((a * a * a - a) * mi + (b * b * b - b) * mj) * (h * h / 6.0);
    s.d1 = (y_[idx(i + 1)] - y_[idx(i)]) / h - (3.0 * a * a - 1.0) / 6.0 * h * mi +
           (3.0 * b * b - 1.0) / 6.0 * h * mj;
    s.d2 = a * mi + b * mj;
    s.d3 = (mj - mi) / h;
    return s;
  }

 private:
  static std::size_t idx(int i) { return static_cast<std::size_t>(i); }
  std::vector<double> t_;
  std::vector<Vec> y_;
  std::vector<Vec> m_;
  bool periodic_ = false;
};

}  // namespace cvslam::sim
