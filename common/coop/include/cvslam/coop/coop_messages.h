#pragma once
// The four cooperation messages of DC-VSLAM (thesis §6.6.3, §6.6.5; docs/conventions.md,
// docs/architecture.md) as plain structs mirroring the lcmtypes agent_summary_t, feature_index_t,
// shared_request_t and shared_landmarks2_t. The core produces and consumes these;
// transport/coop_convert.h converts them to and from LCM. header.seq is numbered per stream by
// DcCooperation.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace cvslam::coop {

struct CoopHeader {
  int agent_id = 0;  ///< sender (UAV id ≥ 1)
  int64_t seq = 0;   ///< per sender and stream, +1 per message
  int64_t t_us = 0;  ///< dataset time of the content [µs]
};

/// Heartbeat + cooperation ellipsoid (thesis §6.6.2), channel TEAM/SUMMARY (agent_summary_t
/// without the per-channel counters, which the process fills).
struct CoopSummary {
  CoopHeader header;
  std::string mode = "dc";
  int64_t boot_id = 0;  ///< random per process start: a change means the agent restarted
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();  ///< mean of the observed features, NED [m]
  Eigen::Vector3d std = Eigen::Vector3d::Zero();   ///< std per NED axis [m] (not scaled)
  int num_features = 0;                            ///< features observed now
  double vehicle_cov_trace = 0.0;                  ///< trace of P_vv's position block [m²]
  /// The sender estimates in a frame of its own (start unknown), not in the team's given
  /// frame: its positions mean nothing here until the frame between the two is found.
  bool own_frame = false;
};

/// The feature indices the sender observes now (§6.6.5), broadcast on UAV<sender>/INDEX.
struct FeatureIndexList {
  CoopHeader header;
  bool true_ids = false;          ///< indices are true landmark ids (feature-level simulation)
  std::vector<uint32_t> indices;  ///< ascending
};

/// "Send me your estimates of these features", on UAV<to_agent>/SHARED_REQ.
struct SharedRequest {
  CoopHeader header;
  int to_agent = 0;
  std::vector<uint32_t> indices;
};

struct SharedLandmark {
  uint32_t index = 0;
  Eigen::Vector3d p_LinN = Eigen::Vector3d::Zero();          ///< NED [m]
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  ///< marginal P_LL [m²]
  std::vector<uint8_t> descriptor;                           ///< empty: none
};

/// The answer to a SharedRequest (or the both_ways return), on UAV<to_agent>/SHARED.
struct SharedLandmarks {
  CoopHeader header;
  int to_agent = 0;
  double vehicle_cov_trace = 0.0;  ///< sender's vehicle position covariance trace [m²]
  /// Provenance: the agents whose information these estimates hold (the sender and every peer
  /// it has fused, transitively), ascending; empty: unknown (treated as correlated).
  std::vector<int> informed_by;
  std::vector<SharedLandmark> landmarks;
  /// The sender's JOINT covariance of the landmarks (3m × 3m, in their order; its diagonal
  /// blocks are the landmarks' covariances); empty: marginals only, and the receiver bounds the
  /// joint by blockdiag(m·P_i).
  Eigen::MatrixXd joint_covariance;
};

/// What one afterFrame emits.
struct CoopOutbox {
  std::optional<CoopSummary> summary;
  std::optional<FeatureIndexList> index;
  std::vector<SharedRequest> requests;
  std::vector<SharedLandmarks> shared;

  bool empty() const { return !summary && !index && requests.empty() && shared.empty(); }
  void clear() {
    summary.reset();
    index.reset();
    requests.clear();
    shared.clear();
  }
};

}  // namespace cvslam::coop
