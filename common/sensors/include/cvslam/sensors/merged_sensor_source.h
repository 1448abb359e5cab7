#pragma once
// Merges per-agent sensor streams into one team stream on the shared play clock (ordering
// rule in sensor_stream.h), optionally cut to the play-time window [start, start + duration].
#include <memory>
#include <optional>
#include <vector>
#include "cvslam/sensors/sensor_stream.h"

namespace cvslam {

struct PlayWindow {
  double start = 0.0;     ///< play time of the first event kept [s]
  double duration = 0.0;  ///< length of the window [s]; ≤ 0: to the end
};

class MergedSensorSource {
 public:
  MergedSensorSource(std::vector<std::unique_ptr<AgentSensorStream>> agents,
                     PlayWindow window = {});
  /// The next event of the team; false at the end (or on an error: see status()).
  bool next(SensorEvent& event);
  /// The first agent error, if any ended the stream.
  const Status& status() const { return status_; }
  /// End of the window (or of the longest agent stream) in play time [µs].
  int64_t endPlayUs() const { return end_us_; }
  int64_t startPlayUs() const { return start_us_; }
  std::vector<int> agentIds() const;

 private:
  bool refill(std::size_t i);
  std::vector<std::unique_ptr<AgentSensorStream>> agents_;
  std::vector<std::optional<SensorEvent>> heads_;
  int64_t start_us_ = 0;
  int64_t end_us_ = 0;
  bool primed_ = false;
  Status status_;
};

}  // namespace cvslam
