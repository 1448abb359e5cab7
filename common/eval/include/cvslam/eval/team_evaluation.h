#pragma once
// Evaluation of a team that started apart (docs/merge.md "Evaluating a team"): each agent's
// own-frame error, its estimate in the team's frame from its merge on (trajectory_team.tum),
// the team's ATE under ONE rigid alignment of all agents' team-frame estimates to their truths
// (as the collaborative SLAM benchmarks evaluate a merged team), the time of each merge, and,
// in simulation, every verified frame relation (relations.csv) against the true relation.
//
// Truth comes from the run folder (a simulation: truth.csv is in the agent's own frame and
// run.json's frames_in_world places each own frame in the world) or from --gt (a recording:
// the ground truth of every folder in one world frame).

#include <optional>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/io/json_file.h"

namespace cvslam {

struct TeamEvaluationOptions {
  double time_tolerance_s = 0.01;  ///< estimate/truth association [s]
  /// χ²₄(0.999): an adopted relation whose error against the truth is beyond it (in its own
  /// covariance) is a wrong merge; a verified candidate beyond it is counted as such.
  double wrong_merge_chi2 = 18.467;
};

/// Every verified relation candidate of one agent (rows of relations.csv with a candidate)
/// against the truth; empty without the frames' truth.
struct RelationCheck {
  int verified = 0;          ///< candidates (pending, adopted, refined, rejected)
  int failed = 0;            ///< verifications that gave no candidate
  int adopted = 0;           ///< adoptions (one per peer unless a peer restarted)
  int wrong_adopted = 0;     ///< adoptions whose candidate's NEES exceeds wrong_merge_chi2
  int over_bound = 0;        ///< candidates whose NEES exceeds wrong_merge_chi2
  std::vector<double> nees;  ///< per candidate, 4 dof (χ²₄ mean 4 when consistent)
  std::vector<double> first_adoption_s;  ///< per adopted peer, the time of its first adoption
};

struct TeamAgentEvaluation {
  int id = 0;
  double flight_s = 0.0;              ///< first to last own estimate [s]
  std::optional<double> own_ate_m;    ///< own estimate against own truth, no alignment
  std::optional<int> root;            ///< whose frame trajectory_team.tum is in
  std::optional<double> merged_at_s;  ///< first team-frame estimate (from the flight's start)
  std::optional<double> coverage;     ///< team-frame span over the flight span
  /// In the root's true frame, no alignment (simulation only: the frames' truth is needed).
  std::optional<double> team_ate_m;
  std::optional<double> team_ate_aligned_m;  ///< its share of the team's one alignment
  std::optional<RelationCheck> relations;
};

struct TeamEvaluation {
  std::vector<TeamAgentEvaluation> agents;
  /// The largest group (agents in one root's frame): its root, and the RMSE of all its
  /// members' team-frame positions after one SE(3) alignment to their truths.
  std::optional<int> root;
  std::optional<double> team_ate_aligned_m;
  std::vector<std::string> notes;
};

/// Reads DIR (and GT when not empty) and evaluates the team. Fails on a missing folder or a
/// malformed file, with the file's name in the message.
Expected<TeamEvaluation> evaluateTeam(const std::string& run_dir, const std::string& gt_dir,
                                      const TeamEvaluationOptions& options = {});

/// The team summary (OUT/team_summary.json, docs/merge.md).
Json teamSummaryJson(const TeamEvaluation& team);

/// A fixed-width per-agent table for the terminal.
std::string teamSummaryTable(const TeamEvaluation& team);

}  // namespace cvslam
