#include "cvslam/slam/gps_updater.h"

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/io/config_node.h"

namespace cvslam {

namespace {
constexpr int kGroupRows = 3;
static_assert(kGpsPoseSize == vehicle_model::kPoseSize, "the GPS Jacobian covers the pose head");
}  // namespace

Status GpsUpdateOptions::load(const ConfigNode& node) {
  node.get("enabled", enabled);
  node.get("use_velocity", use_velocity);
  node.get("sigma_scale", sigma_scale);
  node.check(sigma_scale > 0.0, "sigma_scale", "must be > 0");
  return node.status();
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
  const GpsVector r = gpsMeasurement(fix) - gpsPrediction(pose);
  const GpsJacobian J = gpsJacobian(pose);
  const Eigen::Matrix<double, kGpsObservationSize, kGpsObservationSize> R =
      o_.sigma_scale * o_.sigma_scale * gpsCovariance(fix);
  batch_.reset(state.size(), o_.use_velocity ? 2 * kGroupRows : kGroupRows);
  const int gp = batch_.addObservation(r.head<kGroupRows>(), R.topLeftCorner<3, 3>());
  batch_.setJacobian(gp, veh->index, J.topRows<kGroupRows>());
  if (o_.use_velocity) {
    const int gv = batch_.addObservation(r.tail<kGroupRows>(), R.bottomRightCorner<3, 3>());
    batch_.setJacobian(gv, veh->index, J.bottomRows<kGroupRows>());
  }
  return CovarianceHelper::update(state, batch_, policy, report);
}

}  // namespace cvslam
