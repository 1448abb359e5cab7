#pragma once
// Readers for run records (docs/run_format.md), used by cvslam_eval and tests.

#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/io/run_record.h"

namespace cvslam {

/// Agent ids of the DIR/agent_<id> folders, sorted. Fails if DIR is missing or has none.
Expected<std::vector<int>> listAgentIds(const std::string& run_dir);

/// DIR/run.json; a missing file gives empty fields (not an error), a malformed one fails.
Expected<RunInfo> readRunInfo(const std::string& run_dir);

/// Reads DIR/agent_<id>: trajectory.tum, landmarks.csv and stats.json are required;
/// ins_trajectory.tum, states.csv and truth.csv are optional.
Expected<AgentRun> readAgentRun(const std::string& run_dir, int agent_id);

/// agent_<id>/trajectory_team.tum (its first line names the frame): nothing when the file
/// is absent (the agent never merged); fails on a missing frame line or a malformed pose.
Expected<std::optional<TeamTrajectory>> readTeamTrajectory(const std::string& path);

/// Reads a states.csv / truth.csv style table (t, x..yaw and optionally var_*, cov_i_j).
/// `full_covariance` tells whether off-diagonal terms were present.
Expected<std::vector<StateRecord>> readStateTable(const std::string& path,
                                                  bool* full_covariance = nullptr);

Expected<std::vector<LandmarkRecord>> readLandmarks(const std::string& path);
Expected<RunStats> readRunStats(const std::string& path);

/// Ground truth for agent `id` from a separate folder GT (cvslam_eval --gt): the first of
/// GT/agent_<id>/truth.csv, GT/agent_<id>/trajectory.tum, and the EuRoC ground truth
/// GT/<name>/mav0/state_groundtruth_estimate0/data.csv with <name> in agent_<id>, uav<id>,
/// UAV<id>, <id>, and finally GT/mav0/... (a single-vehicle EuRoC folder, any agent id).
/// `has_velocity` is false for TUM (attitude and position only).
Expected<std::vector<StateRecord>> readGroundTruth(const std::string& gt_dir, int agent_id,
                                                   bool* has_velocity);

/// Ground-truth landmarks GT/landmarks.csv (id,x,y,z header) if present.
Expected<std::vector<LandmarkRecord>> readGroundTruthLandmarks(const std::string& gt_dir);

}  // namespace cvslam
