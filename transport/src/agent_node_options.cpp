// AgentNodeOptions from agent.yaml's `agent:` section (agent_node.h): periods, queues, how the
// filter starts, and the centralised mode's waits.
#include <algorithm>

#include "cvslam/io/config_node.h"
#include "cvslam/lcm/agent_node.h"

namespace cvslam::transport {

Status AgentNodeOptions::load(const ConfigNode& node) {
  node.get("status_period_s", status_period_s);
  node.get("summary_period_s", summary_period_s);
  node.get("counters_period_s", counters_period_s);
  node.get("flush_period_s", flush_period_s);
  node.get("map_period_s", map_period_s);
  node.get("max_wait_s", max_wait_s);
  int imu = static_cast<int>(imu_queue), frames = static_cast<int>(frame_queue);
  node.get("imu_queue", imu);
  node.get("frame_queue", frames);
  node.check(status_period_s > 0.0, "status_period_s", "must be > 0");
  node.check(summary_period_s > 0.0, "summary_period_s", "must be > 0");
  node.check(counters_period_s >= 0.0, "counters_period_s", "must be >= 0 (0: every summary)");
  node.check(flush_period_s > 0.0, "flush_period_s", "must be > 0");
  node.check(map_period_s >= 0.0, "map_period_s", "must be >= 0 (0: never)");
  node.check(max_wait_s > 0.0, "max_wait_s", "must be > 0");
  node.check(imu > 0, "imu_queue", "must be > 0");
  node.check(frames > 0, "frame_queue", "must be > 0");
  imu_queue = static_cast<std::size_t>(std::max(imu, 1));
  frame_queue = static_cast<std::size_t>(std::max(frames, 1));
  if (node.has("initial")) initial_sigma.load(node.child("initial"));
  node.getEnum("start", start,
               {{"known", Start::kKnown},
                {"rest", Start::kRest},
                {"dynamic", Start::kDynamic},
                {"auto", Start::kAuto}});
  unknown_pose.mode = start == Start::kRest      ? UnknownPoseStartMode::kRest
                      : start == Start::kDynamic ? UnknownPoseStartMode::kDynamic
                                                 : UnknownPoseStartMode::kAuto;
  if (node.has("static_init")) unknown_pose.static_init.load(node.child("static_init"));
  if (node.has("dynamic_init")) unknown_pose.dynamic_init.load(node.child("dynamic_init"));
  node.get("start_give_up_s", unknown_pose.give_up_s);
  node.check(unknown_pose.give_up_s > 0.0, "start_give_up_s", "must be > 0");
  if (node.has("cc")) cc.load(node.child("cc"));
  return node.status();
}

Status AgentNodeOptions::Cc::load(const ConfigNode& node) {
  node.get("gs_wait_s", gs_wait_s);
  node.get("gs_timeout_s", gs_timeout_s);
  node.check(gs_wait_s >= 0.0, "gs_wait_s", "must be ≥ 0");
  node.check(gs_timeout_s > 0.0, "gs_timeout_s", "must be > 0");
  return node.status();
}

}  // namespace cvslam::transport
