#include "cvslam/slam/landmark_initialiser.h"

#include <algorithm>
#include <vector>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/slam/linearisation_oracle.h"

namespace cvslam {

LandmarkInitialiser::LandmarkInitialiser(const VariableKey& vehicle, const StereoCamera& camera,
                                         const SlamOptions& options)
    : vehicle_(vehicle), camera_(camera), o_(options) {}

Status LandmarkInitialiser::initialise(SlamState& state, LandmarkBook& book,
                                       const LandmarkArchive& archive,
                                       const StereoFrameObservations& frame, int64_t t_us,
                                       int64_t* next_fresh_id, int* initialised, int max_new,
                                       std::vector<int64_t>* ids) const {
  if (ids != nullptr) ids->assign(frame.observations.size(), -1);
  if (max_new <= 0) return Status::Ok();
  const StateVariable* veh = state.find(vehicle_);
  if (veh == nullptr)
    return Status::Error("landmark initialisation: the vehicle is not in the state");
  const vehicle_model::Pose x = vehicle_model::pose(state, *veh);
  struct NewLandmark {
    double range2;
    std::size_t obs;
    Eigen::Vector3d p_LinN;
  };
  std::vector<NewLandmark> fresh;
  for (std::size_t i = 0; i < frame.observations.size(); ++i) {
    const StereoObservation& obs = frame.observations[i];
    const int64_t id = obs.landmark_id;
    if (id >= 0 &&
        (state.has(VariableKey::landmark(static_cast<uint64_t>(id))) || archive.contains(id))) {
      continue;  // known: updated above, or archived and not chosen this frame
    }
    if (obs.z(0) - obs.z(2) < o_.min_init_disparity_px) continue;
    Eigen::Vector3d p_LinN;
    if (!camera_.triangulate(obs.z, x, &p_LinN).ok()) continue;
    fresh.push_back({(p_LinN - x.p_BinN).squaredNorm(), i, p_LinN});
  }
  // The nearest points are the best triangulated ones (disparity grows as 1/depth).
  const std::size_t n_new = std::min(fresh.size(), static_cast<std::size_t>(max_new));
  std::partial_sort(fresh.begin(), fresh.begin() + static_cast<std::ptrdiff_t>(n_new), fresh.end(),
                    [](const NewLandmark& a, const NewLandmark& b) {
                      return a.range2 < b.range2 || (a.range2 == b.range2 && a.obs < b.obs);
                    });
  const Eigen::Matrix4d R = Eigen::Matrix4d::Identity() * o_.pixel_sigma * o_.pixel_sigma;
  StereoCamera::Matrix3x9d dpL_dxv;
  StereoCamera::Matrix3x4d dpL_dz;
  Eigen::MatrixXd dpL_dvehicle = Eigen::MatrixXd::Zero(3, veh->size);
  vehicle_model::Pose x_true;  // the ideal EKF's diagnostic (linearisation_oracle.h)
  const bool at_truth = oracle_ != nullptr && truePose(*oracle_, t_us, x, &x_true);
  for (std::size_t k = 0; k < n_new; ++k) {
    const StereoObservation& obs = frame.observations[fresh[k].obs];
    Eigen::Vector3d p_LinN;
    if (!camera_.triangulate(obs.z, x, &p_LinN, &dpL_dxv, &dpL_dz).ok()) continue;
    Eigen::Vector3d p_true, p_unused;
    if (at_truth && obs.landmark_id >= 0 && oracle_->landmark(obs.landmark_id, &p_true)) {
      // The inverse observation model's Jacobians at the true pose and noise-free pixels.
      if (!camera_
               .triangulate(camera_.project(x_true, p_true), x_true, &p_unused, &dpL_dxv, &dpL_dz)
               .ok()) {
        continue;
      }
    }
    const int64_t id = obs.landmark_id >= 0 ? obs.landmark_id : (*next_fresh_id)++;
    vehicle_model::poseToBlockJacobian(dpL_dxv, &dpL_dvehicle);
    if (Status s =
            CovarianceHelper::augment(state, VariableKey::landmark(static_cast<uint64_t>(id)),
                                      p_LinN, vehicle_, dpL_dvehicle, dpL_dz, R);
        !s.ok()) {
      return s;
    }
    // u_L = ∂p_L/∂x_v u_v: the landmark inherits the vehicle's tracked yaw direction.
    const Eigen::Vector3d u_L =
        dpL_dvehicle * vehicle_model::yawDirectionAt(x, book.vehicleYawDirection());
    book.add(id, {obs.index, t_us, t_us, obs.descriptor, p_LinN, u_L, true});
    if (ids != nullptr) (*ids)[fresh[k].obs] = id;
    ++*initialised;
  }
  return Status::Ok();
}

bool LandmarkInitialiser::triangulate(const SlamState& state, const StereoObservation& obs,
                                      Eigen::Vector3d* p_LinN, Eigen::Matrix3d* covariance) const {
  const StateVariable* veh = state.find(vehicle_);
  if (veh == nullptr || obs.z(0) - obs.z(2) < o_.min_init_disparity_px) return false;
  const vehicle_model::Pose x = vehicle_model::pose(state, *veh);
  StereoCamera::Matrix3x9d dpL_dxv;
  StereoCamera::Matrix3x4d dpL_dz;
  if (!camera_.triangulate(obs.z, x, p_LinN, &dpL_dxv, &dpL_dz).ok()) return false;
  Eigen::MatrixXd dpL_dvehicle = Eigen::MatrixXd::Zero(3, veh->size);
  vehicle_model::poseToBlockJacobian(dpL_dxv, &dpL_dvehicle);
  const Eigen::MatrixXd P_vv =
      state.covariance().block(veh->index, veh->index, veh->size, veh->size);
  *covariance = dpL_dvehicle * P_vv * dpL_dvehicle.transpose() +
                o_.pixel_sigma * o_.pixel_sigma * dpL_dz * dpL_dz.transpose();
  return true;
}

}  // namespace cvslam
