#pragma once
// Evaluation of a whole run folder (docs/run_format.md cvslam_eval): per agent ATE, INS ATE, RPE,
// NEES, co/Rco, landmark errors, state size, frame time and bandwidth, and the summary JSON.
// Every figure is optional: it is null when its inputs are absent, and `notes` says why.

#include <optional>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/eval/metrics.h"
#include "cvslam/io/json_file.h"
#include "cvslam/io/run_record.h"

namespace cvslam {

class ConfigNode;

struct RunEvaluationOptions {
  double time_tolerance_s = 0.01;          ///< estimate/truth association [s]
  Alignment alignment = Alignment::kNone;  ///< kSE3 for real data in a foreign world frame
  double rpe_segment_m = 10.0;             ///< RPE segment length [m]
  int co_window = 1;                       ///< steps in the true-uncertainty RMS of co

  Status load(const ConfigNode& node);
};

struct AgentEvaluation {
  int id = 0;
  std::optional<double> ate_rmse_m, ins_ate_rmse_m, rpe_m_per_10m;
  std::optional<double> ate_max_m;  ///< largest position error after the alignment
  std::optional<double> nees_mean, nees_position_mean;
  /// Σ NIS / Σ dof of the accepted observations (events.csv): ≈ 1 for a consistent filter,
  /// with or without ground truth.
  std::optional<double> nis_per_dof;
  std::optional<ConsistencyResult> consistency;  ///< co / Rco per state
  std::optional<LandmarkErrorResult> landmark_error;
  std::size_t landmarks = 0;
  std::optional<int> max_state_size;
  std::optional<double> frame_time_ms_median, bytes_sent_per_s;
  std::size_t steps = 0;
  /// Over how much of the flight the figures are: for a ground station's record, the
  /// estimates it made (accepted batches) over the batches the UAV sent (accepted, refused
  /// and dropped on the way, its stats.json); for an agent's own record, steps over frames
  /// (1 unless it stopped estimating). Null when the record does not say.
  std::optional<double> coverage;
  std::optional<double> covered_s;  ///< time from the first to the last estimate [s]
  std::vector<std::string> notes;   ///< why a figure is missing
};

/// Truth for one agent as the evaluation gets it (from the run folder or --gt).
struct AgentTruth {
  std::vector<StateRecord> states;
  bool has_velocity = true;
  std::vector<LandmarkRecord> landmarks;  ///< ground-truth landmarks by id (may be empty)
};

AgentEvaluation evaluateAgent(const AgentRun& run, const AgentTruth& truth,
                              const RunEvaluationOptions& options = {});

/// Reads DIR (and GT when not empty) and evaluates every agent. Fails on a missing folder or
/// a malformed file, with the file's name in the message.
Expected<std::vector<AgentEvaluation>> evaluateRun(const std::string& run_dir,
                                                   const std::string& gt_dir,
                                                   const RunEvaluationOptions& options = {});

/// Summary JSON with the keys of docs/run_format.md plus nees_position_mean, rco, landmark counts.
Json summaryJson(const RunInfo& info, const std::vector<AgentEvaluation>& agents,
                 const RunEvaluationOptions& options);

/// A fixed-width per-agent table for the terminal.
std::string summaryTable(const std::vector<AgentEvaluation>& agents);

}  // namespace cvslam
