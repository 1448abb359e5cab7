#pragma once
// What one agent sends the ground station per stereo frame in centralised mode (CC-VSLAM,
// thesis §6.3; docs/cooperation.md): the IMU samples since its previous batch and the frame's
// associated stereo observations. The transport-free mirror of lcmtypes/observation_batch_t.lcm
// (transport/ converts); the joint filter (cc_team_filter.h) consumes it.
//
// Observation fields used by the joint filter (camera/stereo_observation.h):
//   z            rectified stereo pixels [u_L v_L u_R v_R]
//   landmark_id  the agent's own association: the true landmark id in feature-level
//                simulation (then equal to `index`), else the agent's local landmark id
//                (≥ 0), or −1 when the agent's front end left it unnamed
//   index        feature index (visual word, or the true id in feature-level simulation)
//   descriptor   raw descriptor bytes (image level; may be empty)
//   type         informative only: types 1/2/3 of §6.3.2 are decided by the joint filter from
//                its own map, never trusted from the wire.

#include <cstdint>
#include <string>
#include <vector>

#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/status.h"
#include "cvslam/ins/imu_sample.h"

namespace cvslam::coop {

struct CcObservationBatch {
  int agent_id = 0;
  int64_t t_us = 0;  ///< exposure time of the frame [µs] (= frame.t_us)
  /// IMU samples after the previous batch's time up to and including t_us, ascending.
  std::vector<ImuSample> imu;
  StereoFrameObservations frame;  ///< the agent's associated observations at t_us
};

/// Checks what can be checked without the filter: frame.t_us == t_us, IMU samples finite,
/// strictly ascending and not after t_us, observation pixels finite and below `max_pixel` in
/// magnitude (a negative disparity is a noisy measurement, not a defect), descriptors of one
/// length. The first problem as one line; Ok when the batch is well formed. `defect` (may be
/// null) names the problem's kind: frame_time, imu_not_finite, imu_after_frame, imu_order,
/// pixels or descriptors (the per-reason counts of CcTeamStatistics).
Status validateBatch(const CcObservationBatch& batch, double max_pixel = 1e5,
                     std::string* defect = nullptr);

/// UAV `agent_id`'s part of a text that ends in CcTeamStatistics::refusalSummary() (the
/// ground station's STATUS message, "… UAV3 propagation 1, invalid_pixels 2; UAV4 …"): here
/// "propagation 1, invalid_pixels 2", or empty when it names no refusal of that UAV.
std::string refusalsOf(const std::string& text, int agent_id);

/// Bytes of the batch on the wire (lcmtypes/observation_batch_t.lcm's payload without the
/// LCM envelope): for the traffic figures of runs that do not encode it.
int64_t batchPayloadBytes(const CcObservationBatch& batch);

}  // namespace cvslam::coop
