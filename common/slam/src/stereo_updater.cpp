#include "cvslam/slam/stereo_updater.h"

#include <algorithm>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/ins/vehicle_state_layout.h"
#include "cvslam/slam/linearisation_oracle.h"
#include "cvslam/slam/observability_constraint.h"
#include "cvslam/slam/stereo_second_order_noise.h"

namespace cvslam {

StereoUpdater::StereoUpdater(const VariableKey& vehicle, const StereoCamera& camera,
                             const SlamOptions& options)
    : vehicle_(vehicle), camera_(camera), o_(options) {}

Status StereoUpdater::update(SlamState& state, const LandmarkBook& book,
                             const StereoFrameObservations& frame, int passes, Selection selection,
                             const std::vector<int64_t>& listed, const UpdatePolicy& policy,
                             std::vector<UpdateReport>* reports) {
  // Each pass counts the data once in total: R × passes (scale_noise_per_pass, §5.7.3).
  const double noise_scale = o_.scale_noise_per_pass ? passes : 1.0;
  for (int p = 0; p < passes; ++p) {
    if (Status s = linearise(state, book, frame, selection, listed, Jacobians::kFilter, noise_scale,
                             &batch_);
        !s.ok()) {
      return s;
    }
    UpdateReport u;
    if (batch_.groups() > 0) {
      if (Status s = CovarianceHelper::update(state, batch_, policy, &u); !s.ok()) return s;
    }
    reports->push_back(u);
  }
  return Status::Ok();
}

Status StereoUpdater::linearise(const SlamState& state, const LandmarkBook& book,
                                const StereoFrameObservations& frame, Selection selection,
                                const std::vector<int64_t>& listed, Jacobians jacobians,
                                double noise_scale, MeasurementBatch* batch) const {
  const StateVariable* veh = state.find(vehicle_);
  if (veh == nullptr) return Status::Error("stereo update: the vehicle is not in the state");
  const vehicle_model::Pose x = vehicle_model::pose(state, *veh);
  const bool filter_jacobians = jacobians == Jacobians::kFilter;
  // The ideal EKF's diagnostic (linearisation_oracle.h): H at the true pose and landmarks, for
  // the filter's updates and the iterated ones (loop, rendezvous) alike, whose iterations then
  // move the residual only.
  vehicle_model::Pose x_true;
  const bool at_truth = oracle_ != nullptr && truePose(*oracle_, frame.t_us, x, &x_true);
  const Eigen::Matrix4d R =
      Eigen::Matrix4d::Identity() * (o_.pixel_sigma * o_.pixel_sigma * noise_scale);
  batch->reset(state.size(), 4 * static_cast<int>(frame.observations.size()));
  StereoCamera::Matrix4x9d dz_dxv;
  StereoCamera::Matrix4x3d dz_dpL;
  for (const StereoObservation& obs : frame.observations) {
    const int64_t id = obs.landmark_id;
    if (id < 0) continue;
    if (selection != Selection::kAll) {
      const bool in_list = std::binary_search(listed.begin(), listed.end(), id);
      if (in_list != (selection == Selection::kOnlyListed)) continue;
    }
    const StateVariable* lm = state.find(VariableKey::landmark(static_cast<uint64_t>(id)));
    if (lm == nullptr) continue;
    const Eigen::Vector3d p_LinN = state.value(*lm);
    // Predicted landmark behind the camera: the linearisation is meaningless, skip it.
    if (camera_.landmarkInCamera(x, p_LinN).z() <= 0.0) {
      continue;
    }
    Eigen::Vector4d z_hat;
    const LandmarkBookEntry* record = book.find(id);
    Eigen::Vector3d p_true;
    const bool jacobian_at_truth = at_truth && oracle_->landmark(id, &p_true);
    if (jacobian_at_truth) {
      z_hat = camera_.project(x, p_LinN);
      camera_.project(x_true, p_true, &dz_dxv, &dz_dpL);
    } else if (filter_jacobians && o_.first_estimate_jacobians && record != nullptr) {
      z_hat = camera_.project(x, p_LinN);
      camera_.project(x, record->first_estimate, &dz_dxv, &dz_dpL);
    } else {
      z_hat = camera_.project(x, p_LinN, &dz_dxv, &dz_dpL);
    }
    // At the truth the Jacobians have the true null space already: no projection.
    if (filter_jacobians && !jacobian_at_truth && o_.observability_constrained &&
        record != nullptr && record->constrained) {
      // Range-weighted: the landmark's distance puts attitude and position on one scale.
      const double lever = o_.oc_projection == SlamOptions::OcProjection::kRangeWeighted
                               ? (p_LinN - x.p_BinN).norm()
                               : 1.0;
      TiltDirections tilt;
      if (o_.oc_tilt) tilt = tiltDirections(x, record->first_estimate);
      constrainStereoJacobian(vehicle_model::yawDirectionAt(x, book.vehicleYawDirection()),
                              record->yaw_direction, lever, &dz_dxv, &dz_dpL,
                              o_.oc_tilt ? &tilt : nullptr);
    }
    Eigen::Matrix4d R_obs = R;
    if (filter_jacobians && (o_.second_order_noise || o_.second_order_mean)) {
      const Eigen::MatrixXd& P = state.covariance();
      Eigen::Matrix<double, 12, 12> P_xl;
      P_xl.topLeftCorner<9, 9>() = P.block<9, 9>(veh->index, veh->index);
      P_xl.topRightCorner<9, 3>() = P.block<9, 3>(veh->index, lm->index);
      P_xl.bottomLeftCorner<3, 9>() = P.block<3, 9>(lm->index, veh->index);
      P_xl.bottomRightCorner<3, 3>() = P.block<3, 3>(lm->index, lm->index);
      const StereoSecondOrderTerms terms =
          stereoSecondOrderTerms(camera_, x, p_LinN, P_xl, state.errorChart());
      if (o_.second_order_noise) R_obs += noise_scale * terms.noise;
      if (o_.second_order_mean) z_hat += terms.mean;
    }
    const int g = batch->addObservation(obs.z - z_hat, R_obs);
    if (g < 0) break;
    vehicle_model::setPoseJacobian(*batch, g, *veh, dz_dxv);
    batch->setJacobian(g, *lm, dz_dpL);
  }
  return Status::Ok();
}

}  // namespace cvslam
