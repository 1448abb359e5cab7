#include "cvslam/slam/map_prediction.h"

#include <algorithm>
#include <cmath>

#include "cvslam/io/config_node.h"
#include "cvslam/slam/landmark_lifecycle.h"

namespace cvslam {

Status MapPredictionOptions::load(const ConfigNode& node) {
  node.get("include_archived", include_archived);
  node.get("max_range_m", max_range_m);
  node.get("image_margin_px", image_margin_px);
  node.check(max_range_m > 0.0, "max_range_m", "must be > 0");
  node.check(image_margin_px >= 0.0, "image_margin_px", "must be ≥ 0");
  return node.status();
}

namespace {

/// Keeps a prediction whose left point may fall inside the image (margin plus 3σ).
bool mayBeInImage(const StereoCameraOptions& c, const Eigen::Vector4d& z, const Eigen::Matrix4d& S,
                  double margin) {
  const double mu = margin + 3.0 * std::sqrt(std::max(S(0, 0), 0.0));
  const double mv = margin + 3.0 * std::sqrt(std::max(S(1, 1), 0.0));
  return z(0) >= -mu && z(0) <= c.width - 1 + mu && z(1) >= -mv && z(1) <= c.height - 1 + mv;
}

}  // namespace

Status predictMapObservations(const VisualInertialSlam& slam, const MapPredictionOptions& options,
                              std::vector<PredictedObservation>* predictions) {
  predictions->clear();
  const SlamState& state = slam.state();
  const StereoCamera& camera = slam.camera();
  const StateVariable* veh = state.find(VariableKey::vehicle(0));
  if (veh == nullptr) return Status::Error("predictMapObservations: no vehicle in the state");
  const vehicle_model::Pose x = vehicle_model::pose(state, *veh);
  const Eigen::Vector3d& p_BinN = x.p_BinN;
  const Eigen::MatrixXd& P = state.covariance();
  const Eigen::Matrix<double, 9, 9> P_vv = P.block<9, 9>(veh->index, veh->index);
  const double sigma2 = slam.options().slam.pixel_sigma * slam.options().slam.pixel_sigma;
  const Eigen::Matrix4d R = Eigen::Matrix4d::Identity() * sigma2;
  const double max_range2 = options.max_range_m * options.max_range_m;
  StereoCamera::Matrix4x9d dz_dxv;
  StereoCamera::Matrix4x3d dz_dpL;

  // One landmark: prediction from its mean, covariance and cross-covariance with the vehicle.
  auto predict = [&](int64_t id, const Eigen::Vector3d& p_LinN, const Eigen::Matrix3d& P_LL,
                     const Eigen::Matrix<double, 9, 3>* P_vL, bool archived) {
    if ((p_LinN - p_BinN).squaredNorm() > max_range2) return;
    if (camera.landmarkInCamera(x, p_LinN).z() <= camera.options().min_depth) return;
    PredictedObservation pred;
    pred.landmark_id = id;
    pred.archived = archived;
    pred.z = camera.project(x, p_LinN, &dz_dxv, &dz_dpL);
    const Eigen::Matrix4d cross = P_vL != nullptr
                                      ? Eigen::Matrix4d(dz_dxv * (*P_vL) * dz_dpL.transpose())
                                      : Eigen::Matrix4d::Zero();
    pred.S = dz_dxv * P_vv * dz_dxv.transpose() + dz_dpL * P_LL * dz_dpL.transpose() + cross +
             cross.transpose() + R;
    if (!pred.z.allFinite() || !pred.S.allFinite()) return;
    if (!mayBeInImage(camera.options(), pred.z, pred.S, options.image_margin_px)) return;
    pred.descriptor = slam.descriptorOf(id);
    predictions->push_back(pred);
  };

  // Held landmarks (archived, kept as Schmidt variables) still have their correlation with the
  // vehicle and re-enter exactly at any age: predicted like the state's own.
  for (const StateVariable& v : state.variables()) {
    const bool held = v.key.kind == VariableKey::Kind::kHeldLandmark;
    if (v.key.kind != VariableKey::Kind::kLandmark && !(held && options.include_archived)) continue;
    const Eigen::Matrix<double, 9, 3> P_vL = P.block<9, 3>(veh->index, v.index);
    predict(static_cast<int64_t>(v.key.id), state.value(v), state.covarianceOf(v), &P_vL, held);
  }
  if (options.include_archived) {
    // Landmarks archived less than reactivation_min_age_s ago stay out of the state
    // (VisualInertialSlam::manageMap), so an association to one would never be used; and with
    // their correlation to the vehicle dropped (P_vL = 0) their gate is too wide for a
    // landmark that was in the state a moment ago. Only the ones the filter can re-activate
    // are predicted.
    for (const auto& [id, a] : slam.archive().all()) {
      if (isHeld(state, id) || !mayReenter(state, id, a, slam.time(), slam.options().slam))
        continue;
      predict(id, a.p_LinN, a.covariance, nullptr, true);
    }
  }
  std::sort(predictions->begin(), predictions->end(),
            [](const PredictedObservation& a, const PredictedObservation& b) {
              return a.landmark_id < b.landmark_id;
            });
  return Status::Ok();
}

}  // namespace cvslam
