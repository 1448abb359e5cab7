#include "cvslam/slam/gps_updater.h"

#include <ceres/jet.h>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/io/config_node.h"

namespace cvslam {

namespace {
constexpr int kGroupRows = 3;

/// ∂(R(e) v)/∂e for ZYX Euler angles e, by forward-mode automatic differentiation of the
/// same rotation the INS uses (geometry/euler.h).
Eigen::Matrix3d eulerVelocityJacobian(const Eigen::Vector3d& euler, const Eigen::Vector3d& v_B) {
  using Jet = ceres::Jet<double, 3>;
  Eigen::Matrix<Jet, 3, 1> e;
  for (int i = 0; i < 3; ++i) e(i) = Jet(euler(i), i);
  const Eigen::Matrix<Jet, 3, 1> v_N = rotationBodyToNav(e) * v_B.cast<Jet>();
  Eigen::Matrix3d J;
  for (int r = 0; r < 3; ++r) J.row(r) = v_N(r).v.transpose();
  return J;
}
}  // namespace

Status GpsUpdateOptions::load(const ConfigNode& node) {
  node.get("enabled", enabled);
  node.get("use_velocity", use_velocity);
  node.get("sigma_scale", sigma_scale);
  node.check(sigma_scale > 0.0, "sigma_scale", "must be > 0");
  return node.status();
}

Eigen::Matrix<double, 6, 1> gpsPrediction(const vehicle_model::Pose& pose) {
  Eigen::Matrix<double, 6, 1> h;
  h.head<3>() = pose.p_BinN;
  h.tail<3>() = pose.R_BtoN * pose.v_B;
  return h;
}

Eigen::Matrix<double, 6, vehicle_model::kPoseSize> gpsJacobian(const vehicle_model::Pose& pose) {
  Eigen::Matrix<double, 6, vehicle_model::kPoseSize> J =
      Eigen::Matrix<double, 6, vehicle_model::kPoseSize>::Zero();
  J.block<3, 3>(0, vehicle::kPosition).setIdentity();
  J.block<3, 3>(3, vehicle::kVelocity) = pose.R_BtoN;
  J.block<3, 3>(3, vehicle::kAttitude) =
      pose.attitude == vehicle::Attitude::kEuler
          ? eulerVelocityJacobian(pose.euler, pose.v_B)
          : Eigen::Matrix3d(-pose.R_BtoN *
                            so3::skew(Eigen::Vector3d(pose.v_B)));  // d(R̂ Exp(δθ) v)/dδθ at 0
  return J;
}

Status GpsUpdater::update(SlamState& state, const GpsFix& fix, const UpdatePolicy& policy,
                          UpdateReport* report) {
  const StateVariable* veh = state.find(vehicle_);
  if (veh == nullptr) return Status::Error("gps update: no vehicle in the state");
  if (!fix.p_N.allFinite() || !fix.v_N.allFinite() || !(fix.sigma_p.array() > 0.0).all() ||
      !(fix.sigma_v.array() > 0.0).all()) {
    return Status::Error("gps update: fix with non-finite values or σ ≤ 0");
  }
  const vehicle_model::Pose pose = vehicle_model::pose(state, *veh);
  const Eigen::Matrix<double, 6, 1> h = gpsPrediction(pose);
  const Eigen::Matrix<double, 6, vehicle_model::kPoseSize> J = gpsJacobian(pose);
  const double s2 = o_.sigma_scale * o_.sigma_scale;
  batch_.reset(state.size(), o_.use_velocity ? 2 * kGroupRows : kGroupRows);
  const Eigen::Matrix3d R_p = s2 * fix.sigma_p.array().square().matrix().asDiagonal();
  const int gp = batch_.addObservation(fix.p_N - h.head<3>(), R_p);
  batch_.setJacobian(gp, veh->index, J.topRows<3>());
  if (o_.use_velocity) {
    const Eigen::Matrix3d R_v = s2 * fix.sigma_v.array().square().matrix().asDiagonal();
    const int gv = batch_.addObservation(fix.v_N - h.tail<3>(), R_v);
    batch_.setJacobian(gv, veh->index, J.bottomRows<3>());
  }
  return CovarianceHelper::update(state, batch_, policy, report);
}

}  // namespace cvslam
