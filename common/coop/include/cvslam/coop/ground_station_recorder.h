#pragma once
// The ground station's run record (docs/run_format.md, `ground_station/` of a run folder), the
// one writer of cvslam_run --mode cc (in-process) and of the ground-station process, so both
// leave the same layout:
//   DIR/ground_station/agent_<id>/{trajectory.tum, states.csv, truth.csv (when known),
//                                  stats.json}      per UAV, the agents' format: the joint
//                                  filter's estimate after each of that UAV's batches, so
//                                  `cvslam_eval --run DIR/ground_station` evaluates it
//   DIR/ground_station/landmarks.csv   the joint map (active and archived)
//   DIR/ground_station/stats.json      step time median / p95 / max [ms], state size mean /
//                                      max, batches accepted / rejected per reason, per-UAV
//                                      counts (types 1/2/3), bytes received per stream
//   DIR/ground_station/run.json        mode cc, program, agents (cvslam_eval reads it)

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "cvslam/coop/cc_team_filter.h"
#include "cvslam/core/status.h"
#include "cvslam/io/run_record.h"
#include "cvslam/io/run_writer.h"

namespace cvslam::coop {

class GroundStationRecorder {
 public:
  /// True position of a landmark (simulation), else false.
  using LandmarkTruth = std::function<bool(int64_t landmark_id, Eigen::Vector3d* p_LinN)>;

  GroundStationRecorder();
  ~GroundStationRecorder();

  /// Creates DIR/ground_station/ and writes its run.json from `info` (mode set to "cc",
  /// program kept). Agents' folders are opened on their first step.
  Status open(const std::string& run_dir, const RunInfo& info);

  /// After each processBatch: an accepted step writes the UAV's estimate (and `truth`, its
  /// true 9-entry state when known, may be null) and the step's time and state size; a
  /// rejected one is only counted (the filter's statistics hold the reasons).
  Status addStep(const CcTeamFilter& filter, const CcStepReport& report,
                 const Vector9d* truth = nullptr);
  /// Bytes received per stream ("OBS", ...), for stats.json's traffic figures.
  void addBytesReceived(const std::string& stream, int64_t bytes);
  /// A batch dropped before the filter saw it ("decode", "reordered", "no_vehicle", ...):
  /// stats.json's dropped_per_reason; with the sender's id (> 0) also that agent's
  /// dropped_per_reason, and with the message's size (≥ 0) dropped_bytes_per_reason (min, max).
  void addDropped(const std::string& reason, int agent_id = 0, int64_t bytes = -1);

  /// Flushes the files and writes stats.json as of now (a periodic write of a live process).
  Status flush(const CcTeamFilter& filter);
  /// Writes landmarks.csv from filter.map(), stats.json, and closes everything.
  Status close(const CcTeamFilter& filter, const LandmarkTruth& truth = {});

  const std::string& dir() const { return dir_; }

 private:
  Status writeStats(const CcTeamFilter& filter) const;

  std::string dir_;
  std::map<int, std::unique_ptr<AgentRunWriter>> agents_;
  std::map<std::string, int64_t> bytes_received_;
  std::map<std::string, int64_t> dropped_;
  std::map<int, std::map<std::string, int64_t>> dropped_per_agent_;
  std::map<std::string, std::pair<int64_t, int64_t>> dropped_bytes_;  // min, max
  double t_first_ = 0.0, t_last_ = 0.0;
  bool have_time_ = false;
};

}  // namespace cvslam::coop
