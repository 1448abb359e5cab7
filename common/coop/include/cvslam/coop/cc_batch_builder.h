#pragma once
// Builds an agent's CcObservationBatch per frame (cc_observation_batch.h): the one code path of
// cvslam_run --mode cc and cvslam_agent --mode cc, so both send the ground station the same
// batches. Feed it every IMU sample the agent's filter gets, in order, then take the batch
// after each processed frame.
//
// IMU samples of a batch: every sample given with t_prev < t ≤ t_frame, where t_prev is the
// previous batch's time (the first batch: every sample given since construction or reset();
// the ground station drops those at or before the vehicle's start time). A sample after the
// frame time stays for the next batch.

#include <cstdint>
#include <vector>

#include "cvslam/coop/cc_observation_batch.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/slam/agent_pipeline.h"

namespace cvslam::coop {

class CcBatchBuilder {
 public:
  explicit CcBatchBuilder(int agent_id) : agent_id_(agent_id) {}

  /// Buffers a sample (as given to the agent's filter).
  void addImu(const ImuSample& sample) { imu_.push_back(sample); }
  /// The batch of the agent's last frame: its observations as given to its filter
  /// (frame.observations) and the buffered samples up to the frame time.
  CcObservationBatch takeBatch(const AgentFrame& frame);
  /// The same from a frame given directly (tests, tools).
  CcObservationBatch takeBatch(const StereoFrameObservations& frame);
  /// Forgets the buffered samples (the ground station restarted: the next batch starts anew).
  void reset() { imu_.clear(); }

  int agentId() const { return agent_id_; }

 private:
  int agent_id_;
  std::vector<ImuSample> imu_;
};

}  // namespace cvslam::coop
