#pragma once
// One UAV's sensor data read back from an LCM log (lcm-logger's file), so a recorded team run
// can be played into fresh agents (`cvslam_replay --log FILE`, docs/transport.md "Recorded
// runs"): UAV<id>/IMU, /GT, /FEATURES and /STEREO are decoded and checked as the agent's own
// subscriptions do; every other channel (the agents' estimates, their cooperation) is skipped,
// since fresh agents make those anew. Play time is the UAV's dataset time minus its first
// one in the log (as for EuRoC folders played together).

#include <memory>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/sensors/sensor_stream.h"

struct _lcm_eventlog_t;

namespace cvslam::transport {

class LcmLogSensorStream final : public AgentSensorStream {
 public:
  static Expected<std::unique_ptr<LcmLogSensorStream>> open(const std::string& path, int agent_id);
  /// The UAV ids with sensor data in the log, ascending (an error if none or unreadable).
  static Expected<std::vector<int>> agentsIn(const std::string& path);
  ~LcmLogSensorStream() override;

  int agentId() const override { return agent_id_; }
  bool next(SensorEvent& event) override;
  const Status& status() const override { return status_; }
  int64_t endPlayUs() const override { return end_play_us_; }
  /// Messages skipped because they did not decode or validate.
  int64_t invalid() const { return invalid_; }

 private:
  LcmLogSensorStream(int agent_id, _lcm_eventlog_t* log) : agent_id_(agent_id), log_(log) {}

  int agent_id_;
  _lcm_eventlog_t* log_;
  Status status_;
  int64_t first_us_ = -1, end_play_us_ = 0, invalid_ = 0;
};

}  // namespace cvslam::transport
