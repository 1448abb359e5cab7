#pragma once
// Writers for run records (docs/run_format.md). An estimator run creates one
// AgentRunWriter per agent and calls it each step; nothing here knows about transport.
//
//   AgentRunWriter w;
//   if (auto s = w.open(out_dir, 1); !s.ok()) ...
//   w.addState(t, x_v, P_vv);  w.addTruth(t, x_true);  w.addFrame({t, ms, n});
//   w.addBytesSent(n);  ...  w.writeLandmarks(map);  w.close();

#include <fstream>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/io/run_record.h"

namespace cvslam {

struct AgentRunWriterOptions {
  /// Write the 36 off-diagonal covariance terms (cov_i_j) of the vehicle state, so the
  /// evaluation's NEES uses the full 9×9 covariance rather than its diagonal.
  bool full_covariance = true;
};

/// Median, 95th percentile, maximum and mean of per-step or per-frame times (0 when empty): the
/// ground station's step times, the agents' stage times (RunStats::stage_ms).
struct TimeSummary {
  double median_ms = 0.0, p95_ms = 0.0, max_ms = 0.0, mean_ms = 0.0;
};
TimeSummary summariseTimes(std::vector<double> samples_ms);

/// One line of the per-frame medians, e.g. "frame median 9.1 ms: front end 8.2 (detect 2.5,
/// stereo 1.9, describe 3.3, index 0.1), association 0.5, filter 0.3" ("" without stages).
std::string stageTimesLine(const RunStats& stats);

class AgentRunWriter {
 public:
  AgentRunWriter() = default;
  // Not copyable or movable (open files, close() in the destructor): keep one per agent,
  // in a std::unique_ptr when a container is needed.
  AgentRunWriter(const AgentRunWriter&) = delete;
  AgentRunWriter& operator=(const AgentRunWriter&) = delete;
  ~AgentRunWriter();

  /// Creates DIR/agent_<id>/ and opens trajectory.tum, states.csv and truth.csv.
  Status open(const std::string& run_dir, int agent_id, const AgentRunWriterOptions& options = {});

  /// Estimated state and covariance (9×9 vehicle block) at time t [s]: one line in
  /// states.csv and one pose in trajectory.tum.
  Status addState(double t, const Vector9d& x, const Matrix9d& P);
  /// IMU bias estimate [b_a (m/s²), b_g (rad/s)], its covariance and the true biases (NaN:
  /// unknown) at time t: one line in biases.csv (opened on first use; docs/run_format.md).
  Status addBiases(double t, const Vector6d& b, const Matrix6d& P, const Vector6d& b_true);
  /// True state at time t (simulation): one line in truth.csv.
  Status addTruth(double t, const Vector9d& x_true);
  /// Dead-reckoning (INS-only) state: one pose in ins_trajectory.tum (opened on first use).
  Status addInsState(double t, const Vector9d& x_ins);
  /// The state in the team's frame, that of agent `root` (docs/merge.md): one pose in
  /// trajectory_team.tum (opened on first use). When the root changes (the agent's group met a
  /// group of a lower id) the file starts again, so that it holds one frame.
  Status addTeamState(double t, int root, const Vector9d& x_team);
  void addFrame(const FrameStats& frame) { stats_.frames.push_back(frame); }
  /// One frame's time in one processing stage [ms] (RunStats::stage_ms).
  void addStageTime(const std::string& stage, double ms) { stats_.stage_ms[stage].push_back(ms); }
  void addBytesSent(int64_t bytes) { stats_.bytes_sent += bytes; }
  /// Counts `bytes` in the total and in the stream's own count (stats.json).
  void addBytesSent(const std::string& stream, int64_t bytes) {
    stats_.bytes_sent += bytes;
    stats_.bytes_sent_per_stream[stream] += bytes;
  }
  void addBytesReceived(int64_t bytes) { stats_.bytes_received += bytes; }
  /// Bytes published on one stream so far (replaces the stream's count; cvslam_agent).
  void setBytesSent(const std::string& stream, int64_t bytes) {
    stats_.bytes_sent_per_stream[stream] = bytes;
  }
  void setBytesSentTotal(int64_t bytes) { stats_.bytes_sent = bytes; }

  /// Flushes the files and writes stats.json as of now (an empty landmarks.csv if none yet),
  /// so that a process killed later still leaves a readable record. Stays open.
  Status flush();

  /// Writes landmarks.csv (overwrites; call with the final map, or periodically).
  Status writeLandmarks(const std::vector<LandmarkRecord>& landmarks) const;

  /// Writes stats.json and closes every file. Called by the destructor if needed
  /// (errors are then lost: call it yourself).
  Status close();

  const std::string& dir() const { return dir_; }
  bool isOpen() const { return open_; }
  const RunStats& stats() const { return stats_; }

 private:
  double durationSoFar() const;

  AgentRunWriterOptions options_;
  std::string dir_;
  int agent_id_ = 0;
  std::ofstream states_, truth_, biases_;
  TumWriter trajectory_, ins_, team_;
  int team_root_ = 0;
  RunStats stats_;
  double t_first_ = 0.0, t_last_ = 0.0;
  bool have_time_ = false;
  bool open_ = false;
};

/// Writes a landmarks.csv (docs/run_format.md) at `path`: AgentRunWriter's map, and the ground
/// station's joint map (coop/ground_station_recorder.h).
Status writeLandmarksFile(const std::string& path, const std::vector<LandmarkRecord>& landmarks);

/// Writes DIR/run.json.
Status writeRunInfo(const std::string& run_dir, const RunInfo& info);

/// Writes stats.json content (used by AgentRunWriter; public for tools and tests).
Status writeRunStats(const std::string& path, int agent_id, const RunStats& stats);

}  // namespace cvslam
