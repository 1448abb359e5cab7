#pragma once
// The run record of one agent (docs/run_format.md) written from its AgentPipeline after each
// frame — the one writer of both paths, cvslam_run (every UAV in one process) and
// cvslam_agent (one UAV as a process), so their records have the same layout: states.csv +
// trajectory.tum (estimate), ins_trajectory.tum (dead reckoning), truth.csv (when the truth is
// known), stats.json (per frame time, state size, landmarks, landmark σ; cvslam_agent adds latency
// and bytes per stream), events.csv (per frame filter events), for images frontend.csv, and with
// bias states biases.csv (estimate, 6×6 covariance, the true biases when known).

#include <Eigen/Core>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/io/run_writer.h"
#include "cvslam/slam/agent_pipeline.h"
#include "cvslam/slam/vehicle_estimate.h"

namespace cvslam {

/// landmarks.csv records of a map (active and archived landmarks), with their true position
/// where `truth` knows it: AgentRunRecorder's and the ground station's
/// (coop/ground_station_recorder.h).
std::vector<LandmarkRecord> landmarkRecords(
    const std::vector<MapLandmark>& map,
    const std::function<bool(int64_t landmark_id, Eigen::Vector3d* p_LinN)>& truth);

class AgentRunRecorder {
 public:
  /// True position of a landmark of the map when known (simulation), else false.
  using LandmarkTruth = std::function<bool(int64_t landmark_id, Eigen::Vector3d* p_LinN)>;

  /// Creates DIR/agent_<id>/ and opens its files; `images` adds frontend.csv (else it is
  /// opened with the first frame that went through the image path).
  Status open(const std::string& run_dir, int agent_id, bool images);
  bool isOpen() const { return writer_ != nullptr; }

  /// Records the pipeline's last frame. `truth`: the true vehicle state at the frame (null:
  /// unknown); `latency_ms`: arrival → pose published (NaN: not measured).
  Status addFrame(const AgentPipeline& agent, const Vector9d* truth,
                  double latency_ms = std::numeric_limits<double>::quiet_NaN());
  /// The same with the vehicle estimate recorded (states.csv, trajectory.tum) replaced by
  /// `adopted` when not null: centralised mode, where the agent adopts the ground station's
  /// estimate of its frame (coop/cc_team_filter.h). Everything else is the agent's own.
  Status addFrame(const AgentPipeline& agent, const Vector9d* truth, double latency_ms,
                  const VehicleEstimate* adopted);

  /// The true IMU biases [b_a (m/s²), b_g (rad/s)] at the next addFrame (simulation): they go
  /// to that frame's row of biases.csv (NaN when not given).
  void setBiasTruth(const Vector6d& b) { bias_truth_ = b; }
  /// Writes landmarks.csv from the agent's map (active and archived landmarks).
  Status writeMap(const VisualInertialSlam& slam, const LandmarkTruth& truth);

  /// Flushes everything written so far and stats.json (periodic output of a live agent).
  Status flush();
  /// Writes stats.json and closes the files.
  Status close();

  AgentRunWriter& writer() { return *writer_; }
  const AgentRunWriter& writer() const { return *writer_; }

 private:
  Status openFrontend();

  std::unique_ptr<AgentRunWriter> writer_;
  std::ofstream events_, frontend_;
  Vector6d bias_truth_ = Vector6d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::string dir_;
};

}  // namespace cvslam
