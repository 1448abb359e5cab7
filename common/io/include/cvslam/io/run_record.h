#pragma once
// What an estimator run leaves on disk per agent (docs/run_format.md; formats in
// docs/run_format.md), as plain structs shared by the writer and the reader.
//
//   DIR/run.json                      mode, filter, ... of the whole run (RunInfo)
//   DIR/agent_<id>/trajectory.tum     estimated pose per step (TUM)
//   DIR/agent_<id>/ins_trajectory.tum dead reckoning from the same IMU data (optional)
//   DIR/agent_<id>/states.csv         estimated vehicle state + covariance per step (optional)
//   DIR/agent_<id>/truth.csv          true vehicle state at the same times (optional)
//   DIR/agent_<id>/landmarks.csv      final map: mean, variances, truth when known
//   DIR/agent_<id>/stats.json         per-frame time, state size, bytes sent

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cvslam/io/tum_trajectory.h"

namespace cvslam {

using Vector9d = Eigen::Matrix<double, 9, 1>;
using Matrix9d = Eigen::Matrix<double, 9, 9>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// Names of the nine vehicle states in files, in state order (vehicle_state_layout.h).
inline const char* const kVehicleStateNames[9] = {"x", "y",    "z",     "u",  "v",
                                                  "w", "roll", "pitch", "yaw"};

/// Vehicle state [p_BinN, v_B, euler] at time t with its covariance (or only its diagonal).
struct StateRecord {
  double t = 0.0;                 ///< [s]
  Vector9d x = Vector9d::Zero();  ///< estimate (or truth)
  Matrix9d P = Matrix9d::Zero();  ///< covariance; off-diagonals zero if not recorded
};

struct LandmarkRecord {
  int64_t id = 0;
  Eigen::Vector3d p_LinN = Eigen::Vector3d::Zero();  ///< estimate [m]
  Eigen::Vector3d var = Eigen::Vector3d::Zero();     ///< variances of x, y, z [m²]
  std::optional<Eigen::Vector3d> truth;              ///< true position when known [m]
};

/// One processed stereo frame.
struct FrameStats {
  double t = 0.0;        ///< dataset time [s]
  double time_ms = 0.0;  ///< wall time spent on the frame [ms]
  int state_size = 0;    ///< length of the filter state after the frame
  int landmarks = -1;    ///< landmarks in the state (−1: not recorded)
  /// Mean landmark standard deviation sqrt(trace(P_LL)/3) over the state's landmarks [m]
  /// (NaN: not recorded). Drives the "landmark uncertainty over time" plot.
  double landmark_sigma_mean_m = std::numeric_limits<double>::quiet_NaN();
  /// Wall time from the frame's arrival to the publication of its pose [ms] (cvslam_agent;
  /// NaN: not recorded).
  double latency_ms = std::numeric_limits<double>::quiet_NaN();
};

struct RunStats {
  double duration_s = 0.0;  ///< dataset time covered by the run [s]
  int64_t bytes_sent = 0;   ///< payload bytes this agent published (all channels)
  int64_t bytes_received = 0;
  /// Payload bytes published per stream ("SUMMARY", "INDEX", ...), when the driver counts
  /// them; stats.json: bytes_sent_per_stream and their rates bytes_sent_per_s.
  std::map<std::string, int64_t> bytes_sent_per_stream;
  std::vector<FrameStats> frames;
  /// Per-frame time of each processing stage [ms] ("front_end.detect", …, "filter"), when
  /// the driver times them; stats.json: stage_ms {stage: {frames, mean, median, p95}}.
  std::map<std::string, std::vector<double>> stage_ms;
};

/// Run-wide facts written once by the driver (cvslam_run, the agents' launcher).
struct RunInfo {
  std::string mode;    ///< single | dc | cc ("" when unknown)
  std::string filter;  ///< ekf | nhinf ("" when unknown)
  std::string map;     ///< knearest | full ("" when unknown)
  std::string scenario;
  // What else is needed to reproduce the run from its folder (every agent's options are in
  // agent_<id>/config_used.yaml); absent when unknown or not applicable.
  std::optional<uint64_t> seed;      ///< the scenario's seed as run (after --seed)
  std::optional<double> duration_s;  ///< simulated duration as run (after --duration) [s]
  std::string sensing;               ///< features | images (simulation)
  std::string world;                 ///< --world (render world kind), when given
  std::string pixel_noise;           ///< --pixel-noise, when given
  std::vector<int> agents;           ///< the UAVs that ran (ids)
  /// Simulation truth, as truth.csv is: the own frame of each agent that started unknown, in
  /// the scenario's world, [t_N t_E t_D ψ] with p_world = R_z(ψ) p_own + t (docs/merge.md).
  /// An agent not listed estimates in the world frame.
  std::map<int, Eigen::Vector4d> frames_in_world;
  /// cvslam_run --linearise-at-truth: the filters took their Jacobians at the simulator's
  /// truth (the ideal EKF, a consistency diagnostic), not an estimator a UAV could run.
  bool linearised_at_truth = false;
  std::string config;   ///< the configuration file given (before overrides)
  std::string program;  ///< cvslam_run | cvslam_agent
  /// The code the run came from (`git describe --always --dirty` at build time): with
  /// config_used.yaml, which holds the file and overrides but not the built-in defaults,
  /// it pins every option. writeRunInfo fills it in when empty.
  std::string commit;
};

/// An agent's estimate in its team's frame, agent_<id>/trajectory_team.tum, whose first line
/// names the frame: "# frame: agent_<root>".
struct TeamTrajectory {
  int root = 0;  ///< whose frame
  std::vector<TumPose> poses;
};
inline constexpr const char* kTeamFramePrefix = "frame: agent_";
std::string teamFrameComment(int root);  ///< kTeamFramePrefix + root

/// Everything read back for one agent.
struct AgentRun {
  int id = 0;
  std::string dir;
  std::vector<TumPose> trajectory;
  std::optional<std::vector<TumPose>> ins_trajectory;
  std::optional<TeamTrajectory> team;  ///< trajectory_team.tum, when the agent merged
  std::vector<StateRecord> states;     ///< empty when states.csv is absent
  bool states_full_covariance = false;
  std::vector<StateRecord> truth;  ///< empty when no truth was found
  std::vector<LandmarkRecord> landmarks;
  RunStats stats;
  /// Σ nis and Σ nis_dof over events.csv (absent: no events.csv or one without these columns).
  std::optional<double> nis_sum;
  std::optional<long> nis_dof_sum;
};

/// "DIR/agent_<id>".
std::string agentDir(const std::string& run_dir, int agent_id);

}  // namespace cvslam
