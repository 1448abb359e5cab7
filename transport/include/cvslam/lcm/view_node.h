#pragma once
// The bus side of cvslam_view (docs/view.md): subscribes to the team's channels and feeds a
// view::TeamView, which clients read as JSON deltas. Callbacks run on the bus's receive
// thread and only convert and store under one mutex (never wait on a client), so a slow or
// closed browser never holds the bus. Malformed messages are dropped by the bus's decoder and
// counted here per channel.
//
// Subscribed: UAV*/POSE (estimate, covariance, landmark counts), UAV*/GT (truth, NEES),
// UAV*/MAP (the agent's landmarks), GS/MAP (the joint map), TEAM/SUMMARY, UAV*/INDEX and
// UAV*/OBS (traffic; OBS also a link to the ground station), UAV<j>/SHARED_REQ and
// UAV<j>/SHARED for j = 1..max_agent_id (links i → j), UAV<j>/GS_STATE (the ground station's
// estimate of j), and UAV*/FEATURES, UAV*/STEREO (frame arrivals, for the latency) unless
// latency is off.

#include <memory>
#include <mutex>
#include <string>

#include "cvslam/core/status.h"
#include "cvslam/io/json_file.h"
#include "cvslam/lcm/lcm_bus.h"
#include "cvslam/view/team_view.h"

namespace cvslam::transport {

struct ViewNodeOptions {
  std::string url = kDefaultLcmUrl;
  std::shared_ptr<const TeamKey> auth_key;  ///< set: cooperation messages must verify
  /// Directed channels (UAV<j>/SHARED_REQ, /SHARED, /GS_STATE) are subscribed for j = 1..this;
  /// LCM subscriptions are names, and a directed message's receiver is only in its name.
  int max_agent_id = 16;
  /// Subscribe to the sensor frames (UAV*/FEATURES, UAV*/STEREO) to measure the latency from a
  /// frame to its estimate. Decoding images costs CPU; off keeps the viewer cheapest.
  bool latency = true;
  view::TeamViewOptions view;
};

class ViewNode {
 public:
  static Expected<std::unique_ptr<ViewNode>> create(const ViewNodeOptions& options);
  Status start();
  void stop();
  /// What the client behind `cursor` has not seen (team_view.h), under the node's lock.
  Json delta(view::ViewCursor& cursor);
  int64_t malformed();
  int64_t messages();

 private:
  explicit ViewNode(const ViewNodeOptions& options);
  Status subscribe();
  double now() const;
  template <typename Fn>
  void locked(Fn&& fn);

  ViewNodeOptions o_;
  std::unique_ptr<LcmBus> bus_;
  std::mutex mutex_;
  view::TeamView view_;
};

}  // namespace cvslam::transport
