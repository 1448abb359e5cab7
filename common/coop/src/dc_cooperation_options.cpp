// DcCooperation's options (config section `coop:`) and event names (dc_cooperation.h).

#include <string>

#include "cvslam/coop/dc_cooperation.h"
#include "cvslam/io/config_node.h"

namespace cvslam::coop {

std::string coopEventName(CoopEventKind kind) {
  switch (kind) {
    case CoopEventKind::kPeerJoined:
      return "peer_joined";
    case CoopEventKind::kPeerRestarted:
      return "peer_restarted";
    case CoopEventKind::kPeerLost:
      return "peer_lost";
    case CoopEventKind::kIndexSent:
      return "index_sent";
    case CoopEventKind::kRequestSent:
      return "request_sent";
    case CoopEventKind::kSharedSent:
      return "shared_sent";
    case CoopEventKind::kFused:
      return "fused";
    case CoopEventKind::kRequestTimeout:
      return "request_timeout";
  }
  return "unknown";
}

Status DcCooperationOptions::load(const ConfigNode& node) {
  node.get("coop_sigma", coop_sigma);
  node.get("min_semi_axis_m", min_semi_axis_m);
  node.get("summary_period_s", summary_period_s);
  node.get("exchange_period_s", exchange_period_s);
  node.get("reask_period_s", reask_period_s);
  node.get("peer_timeout_s", peer_timeout_s);
  node.get("min_request_timeout_s", min_request_timeout_s);
  node.get("request_timeout_s", request_timeout_s);
  node.get("max_message_age_s", max_message_age_s);
  std::string method = ciMethodName(ci_method);
  node.get("ci_method", method);
  if (Expected<CiMethod> m = parseCiMethod(method); m.ok()) {
    ci_method = m.value();
  } else {
    node.check(false, "ci_method", m.status().message());
  }
  node.get("both_ways", both_ways);
  node.get("max_landmarks_per_message", max_landmarks_per_message);
  node.get("max_indices_per_message", max_indices_per_message);
  node.get("gate_probability", gate_probability);
  node.get("max_descriptor_distance", max_descriptor_distance);
  node.get("max_position_m", max_position_m);
  node.get("max_landmark_variance_m2", max_landmark_variance_m2);
  node.get("min_landmark_variance_m2", min_landmark_variance_m2);
  node.get("min_omega", min_omega);
  node.get("require_vehicle_gain", require_vehicle_gain);
  node.get("use_provenance", use_provenance);
  node.get("map_shared_landmarks", map_shared_landmarks);
  node.get("offer_archived", offer_archived);
  node.get("max_offered_landmarks", max_offered_landmarks);
  node.check(max_offered_landmarks >= 1, "max_offered_landmarks", "must be ≥ 1");
  node.get("consistency_window", consistency.window);
  node.get("consistency_probability", consistency.probability);
  node.get("include_vehicle_uncertainty", include_vehicle_uncertainty);
  node.get("max_queued_messages", max_queued_messages);
  node.get("max_peers", max_peers);
  node.check(max_peers >= 1, "max_peers", "must be ≥ 1");
  const ConfigNode merge = node.child("merge");
  merge.get("place_period_s", place_period_s);
  merge.check(place_period_s > 0.0, "place_period_s", "must be > 0");
  merge.get("max_place_backoff_s", max_place_backoff_s);
  merge.check(max_place_backoff_s >= place_period_s, "max_place_backoff_s",
              "must be >= place_period_s");
  (void)aligner.load(merge.child("aligner"));  // errors are the file's (node.status())
  (void)relations.load(merge.child("relations"));
  node.check(coop_sigma > 0.0, "coop_sigma", "must be > 0");
  node.check(min_semi_axis_m > 0.0, "min_semi_axis_m", "must be > 0");
  node.check(summary_period_s > 0.0, "summary_period_s", "must be > 0");
  node.check(exchange_period_s >= 0.0, "exchange_period_s", "must be ≥ 0 (0: every frame)");
  node.check(reask_period_s >= 0.0, "reask_period_s", "must be ≥ 0 (0: ask every time)");
  node.check(peer_timeout_s > 0.0 && request_timeout_s > 0.0 && max_message_age_s > 0.0,
             "peer_timeout_s", "peer_timeout_s, request_timeout_s, max_message_age_s must be > 0");
  node.check(min_request_timeout_s > 0.0 && min_request_timeout_s <= request_timeout_s,
             "min_request_timeout_s", "must be > 0 and ≤ request_timeout_s");
  node.check(max_landmarks_per_message >= 1, "max_landmarks_per_message", "must be ≥ 1");
  node.check(max_indices_per_message >= 1, "max_indices_per_message", "must be ≥ 1");
  node.check(gate_probability > 0.0 && gate_probability < 1.0, "gate_probability",
             "must be in (0, 1)");
  node.check(max_descriptor_distance >= 0.0, "max_descriptor_distance", "must be ≥ 0");
  node.check(max_position_m > 0.0, "max_position_m", "must be > 0");
  node.check(min_landmark_variance_m2 > 0.0 && max_landmark_variance_m2 > min_landmark_variance_m2,
             "max_landmark_variance_m2",
             "need 0 < min_landmark_variance_m2 < max_landmark_variance_m2");
  node.check(min_omega > 0.0 && min_omega < 1.0, "min_omega", "must be in (0, 1)");
  node.check(consistency.window >= 0, "consistency_window", "must be ≥ 0 (0: no test)");
  node.check(consistency.probability > 0.0 && consistency.probability < 1.0,
             "consistency_probability", "must be in (0, 1)");
  node.check(max_queued_messages >= 1, "max_queued_messages", "must be ≥ 1");
  return node.status();
}

}  // namespace cvslam::coop
