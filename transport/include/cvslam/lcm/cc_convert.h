#pragma once
// Conversions of centralised cooperation (CC-VSLAM, docs/ground_station.md, thesis §6.3)
// between core structs and their lcmtypes: CcObservationBatch ↔ observation_batch_t (UAV<id>/OBS),
// VehicleEstimate ↔ gs_state_t (UAV<id>/GS_STATE) and agent_state_t (UAV<id>/POSE, the agent's
// own estimate the ground station starts a vehicle from), the joint map → map_t (GS/MAP).
// toMessage() finalizes the count fields; received messages come through decodeMessage()
// (codec.h, wire structure, counts and finite numbers) before fromMessage(), which adds the
// semantic checks of coop::validateBatch (IMU ascending and not after the frame, pixels
// within bounds). Indices are uint32 in the core and travel as the
// same bit pattern in int32. cvslam_agent, cvslam_ground_station and cvslam_run --mode cc
// (in-process, through the encoding) use these and no other conversion.

#include <cstdint>
#include <string>
#include <vector>

#include "cvslam/coop/cc_observation_batch.h"
#include "cvslam/core/status.h"
#include "cvslam/lcm/message_types.h"
#include "cvslam/slam/vehicle_estimate.h"
#include "cvslam/slam/visual_inertial_slam.h"

namespace cvslam::transport {

/// Fills state_dim, state and covariance (row-major) of agent_state_t or gs_state_t with a
/// vehicle estimate, the vector copied as the core gives it.
template <typename Msg>
void setVehicleEstimate(Msg& msg, const Eigen::VectorXd& x_v, const Eigen::MatrixXd& P_v) {
  msg.state_dim = static_cast<int32_t>(x_v.size());
  msg.state.assign(x_v.data(), x_v.data() + x_v.size());
  msg.covariance.clear();
  msg.covariance.reserve(static_cast<std::size_t>(P_v.size()));
  for (int r = 0; r < P_v.rows(); ++r)
    for (int c = 0; c < P_v.cols(); ++c) msg.covariance.push_back(P_v(r, c));
  msg.covariance_size = static_cast<int32_t>(msg.covariance.size());
}

/// An agent's map (active and archived landmarks) on UAV<id>/MAP, for displays: positions
/// and one spread sqrt(trace(P_LL)/3) per landmark.
Expected<cvslam::agent_map_t> agentMapMessage(int agent_id, int64_t t_us,
                                              const std::vector<MapLandmark>& map);

/// An agent's estimate on UAV<id>/POSE (num_landmarks, num_archived: 0 unless set after).
cvslam::agent_state_t agentStateMessage(int agent_id, const std::string& filter, int64_t t_us,
                                        const Eigen::VectorXd& x_v, const Eigen::MatrixXd& P_v);

/// header.agent_id = batch.agent_id, header.utime = batch.t_us (seq: stamped by the bus). IMU
/// samples and pixels travel in single precision (observation_batch_t.lcm): the batch that
/// arrives is the one sent rounded to float, in cvslam_run --mode cc as over LCM.
Expected<cvslam::observation_batch_t> toMessage(const coop::CcObservationBatch& batch);
/// The batch of a decoded message; an error when it fails coop::validateBatch.
Expected<coop::CcObservationBatch> fromMessage(const cvslam::observation_batch_t& msg);

/// The ground station's estimate of one vehicle (header.agent_id = 0, the ground station).
Expected<cvslam::gs_state_t> toMessage(const VehicleEstimate& estimate, const std::string& filter,
                                       int64_t map_version);
VehicleEstimate fromMessage(const cvslam::gs_state_t& msg);

/// An agent's own estimate (UAV<id>/POSE), as the ground station takes it to (re)start a
/// vehicle.
VehicleEstimate estimateOf(const cvslam::agent_state_t& msg);

/// The joint map at `t_us` (header.agent_id = 0): every landmark, covariance as the upper
/// triangle xx xy xz yy yz zz.
Expected<cvslam::map_t> toMessage(const std::vector<MapLandmark>& map, int64_t t_us,
                                  int64_t map_version);

}  // namespace cvslam::transport
