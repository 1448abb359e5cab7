#include "cvslam/scenario/tum_trajectory.h"

#include <cmath>
#include <vector>

#include "cvslam/geometry/euler.h"
#include "cvslam/io/tum_trajectory.h"

namespace cvslam::sim {

namespace {

struct TumRow {
  double t;
  Eigen::Vector3d p;
  Eigen::Vector4d q;  // (w, x, y, z)
};

}  // namespace

Expected<std::shared_ptr<TumTrajectory>> TumTrajectory::load(const TumTrajectoryOptions& o) {
  if (!(o.knot_interval > 0.0)) return Status::Error(o.file + ": knot_interval must be > 0");
  // The one TUM parser of the project (io/tum_trajectory.h) checks fields and time order.
  auto poses = readTumTrajectory(o.file);
  if (!poses.ok()) return poses.status();
  std::vector<TumRow> rows;
  rows.reserve(poses->size());
  for (const TumPose& pose : *poses) {
    const Eigen::Quaterniond q = pose.q_BtoN.normalized();
    rows.push_back({pose.t, pose.p_BinN, Eigen::Vector4d(q.w(), q.x(), q.y(), q.z())});
  }
  if (rows.size() < 4) return Status::Error(o.file + ": fewer than 4 poses");

  auto traj = std::shared_ptr<TumTrajectory>(new TumTrajectory());
  if (o.z_up_to_ned) traj->R_WtoN_ = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  traj->R_TtoB_ = o.R_TtoB;
  traj->start_time_ = rows.front().t;
  const double t_end = rows.back().t - rows.front().t;

  // Knots every knot_interval: positions averaged over the window, quaternion of the sample
  // nearest to the knot with its sign kept continuous.
  std::vector<double> knots;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector4d> quats;
  const int n_knots = std::max(2, static_cast<int>(std::floor(t_end / o.knot_interval)) + 1);
  std::size_t lo = 0;
  for (int k = 0; k < n_knots; ++k) {
    const double tk = std::min(k * o.knot_interval, t_end);
    if (!knots.empty() && tk <= knots.back()) break;
    const double a = tk - 0.5 * o.knot_interval, b = tk + 0.5 * o.knot_interval;
    while (lo < rows.size() && rows[lo].t - traj->start_time_ < a) ++lo;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    std::size_t nearest = lo;
    for (std::size_t i = lo; i < rows.size() && rows[i].t - traj->start_time_ <= b; ++i) {
      sum += rows[i].p;
      ++count;
      if (std::abs(rows[i].t - traj->start_time_ - tk) <
          std::abs(rows[nearest].t - traj->start_time_ - tk))
        nearest = i;
    }
    if (count == 0) continue;  // gap in the file: the spline bridges it
    nearest = std::min(nearest, rows.size() - 1);
    Eigen::Vector4d q = rows[nearest].q;
    if (!quats.empty() && q.dot(quats.back()) < 0.0) q = -q;
    knots.push_back(tk);
    positions.push_back(traj->R_WtoN_ * (sum / count));
    quats.push_back(q);
  }
  if (knots.size() < 2) return Status::Error(o.file + ": too few poses for a spline");
  if (o.start_at_offset) {
    const Eigen::Vector3d shift = o.offset - positions.front();
    for (auto& p : positions) p += shift;
  }
  traj->duration_ = knots.back();
  traj->position_ = CubicSpline<3>(knots, positions, false);
  traj->quat_ = CubicSpline<4>(knots, quats, false);
  return traj;
}

TrajectoryState TumTrajectory::state(double t) const {
  TrajectoryState s;
  s.t = t;
  const SplineSample<3> p = position_.sample(t);
  s.p_BinN = p.value;
  s.v_N = p.d1;
  s.a_N = p.d2;
  const SplineSample<4> qs = quat_.sample(t);
  const double norm = qs.value.norm();
  const Eigen::Vector4d qn = qs.value / norm;
  const Eigen::Vector4d qn_dot = (qs.d1 - qn * qn.dot(qs.d1)) / norm;  // d/dt (s / |s|)
  const Eigen::Quaterniond q_WT(qn(0), qn(1), qn(2), qn(3));
  const Eigen::Quaterniond q_dot(qn_dot(0), qn_dot(1), qn_dot(2), qn_dot(3));
  const Eigen::Vector3d omega_T = 2.0 * (q_WT.conjugate() * q_dot).vec();
  const Eigen::Matrix3d R_BtoN = R_WtoN_ * q_WT.toRotationMatrix() * R_TtoB_.transpose();
  s.R_NtoB = R_BtoN.transpose();
  s.omega_B = R_TtoB_ * omega_T;
  s.euler = eulerFromRotationNavToBody(s.R_NtoB);
  s.euler_rates = eulerRates(s.euler, s.omega_B);
  return s;
}

}  // namespace cvslam::sim
