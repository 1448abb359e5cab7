#include "cvslam/scenario/scenario.h"

#include <algorithm>

#include <cmath>
#include <set>

#include "cvslam/io/config_node.h"

namespace cvslam::sim {

Status AgentSpec::load(const ConfigNode& node, const std::string& base_dir) {
  node.require("id", id);
  node.check(id > 0, "id", "must be > 0");
  trajectory.load(node.child("trajectory"), base_dir);
  initial.load(node.child("initial_uncertainty"));
  imu.load(node.child("imu"));
  if (!imu.recording.empty() && imu.recording.front() != '/' && !base_dir.empty())
    imu.recording = base_dir + "/" + imu.recording;
  camera.load(node.child("camera"));
  node.get("camera_rate_hz", camera_rate_hz);
  node.check(camera_rate_hz > 0.0 && camera_rate_hz <= 1000.0, "camera_rate_hz",
             "must be in (0, 1000]");
  node.get("camera_delay_s", camera_delay_s);
  node.check(camera_delay_s >= 0.0 && camera_delay_s * camera_rate_hz < 1.0, "camera_delay_s",
             "must be in [0, 1 / camera_rate_hz)");
  pixel_noise.load(node.child("pixel_noise"));
  has_gps = node.has("gps");
  if (has_gps) gps.load(node.child("gps"));
  std::string start = "known";
  node.get("start", start);
  node.check(start == "known" || start == "unknown", "start", "must be known or unknown");
  start_known = start != "unknown";
  // A GPS fix is in the team's frame: it would tell the agent where it is.
  node.check(start_known || !has_gps, "start", "unknown needs no gps section");
  return node.status();
}

Status Scenario::overrideStarts(bool known) {
  for (AgentSpec& agent : agents) {
    // A GPS fix is in the team's frame: it would tell the agent where it is.
    if (!known && agent.has_gps)
      return Status::Error("agent " + std::to_string(agent.id) +
                           ": an unknown start needs no gps section");
    agent.start_known = known;
  }
  return Status::Ok();
}

void extendByFlight(const Trajectory& trajectory, double time_offset, double duration,
                    Eigen::AlignedBox2d* area) {
  const int steps = static_cast<int>(std::ceil(duration / 0.5));
  for (int k = 0; k <= steps; ++k) {
    const double t = std::min(k * 0.5, duration) + time_offset;
    area->extend(trajectory.state(t).p_BinN.head<2>());
  }
}

Status Scenario::load(const ConfigNode& node, const std::string& base_dir) {
  source = node.source();
  node.get("name", name);
  int64_t seed_value = static_cast<int64_t>(seed);
  node.get("seed", seed_value);
  node.check(seed_value >= 0, "seed", "must be >= 0");
  seed = static_cast<uint64_t>(seed_value);
  node.get("duration", duration);
  node.check(duration > 0.0, "duration", "must be > 0 s");
  world.load(node.child("world"));
  render_yaml = node.sectionText("render");
  agents.clear();
  const auto items = node.sequence("agents");
  if (!node.has("agents")) {
    node.check(false, "agents", "required key is missing");
  } else {
    node.check(!items.empty(), "agents", "need at least one agent");
  }
  std::set<int> ids;
  for (const ConfigNode& item : items) {
    AgentSpec a;
    a.load(item, base_dir);
    item.check(ids.insert(a.id).second, "id", "duplicate agent id " + std::to_string(a.id));
    agents.push_back(a);
  }
  if (!node.status().ok()) return node.status();
  // Open trajectories must cover the whole run.
  world_region.setEmpty();
  for (std::size_t i = 0; i < agents.size(); ++i) {
    auto traj = agents[i].trajectory.build();
    const std::string key = "agents[" + std::to_string(i) + "].trajectory";
    if (!traj.ok()) return Status::Error(node.where(key) + ": " + traj.status().message());
    const double needed = agents[i].trajectory.time_offset + duration;
    if ((*traj)->duration() + 1e-9 < needed) {
      return Status::Error(node.where(key) + ": trajectory lasts " +
                           std::to_string((*traj)->duration()) + " s, the scenario needs " +
                           std::to_string(needed) + " s");
    }
    extendByFlight(**traj, agents[i].trajectory.time_offset, duration, &world_region);
  }
  return node.finish();
}

Expected<World> Scenario::generateWorld() const {
  // The area the world is laid out around: the whole team's (world_region), else these agents'.
  Eigen::AlignedBox2d region = world_region;
  if (region.isEmpty()) {
    for (const AgentSpec& a : agents) {
      auto traj = a.trajectory.build();
      if (!traj.ok()) return traj.status();
      extendByFlight(**traj, a.trajectory.time_offset, duration, &region);
    }
  }
  if (region.isEmpty()) return Status::Error(source + ": no agents");
  region.min().array() -= world.margin + 1.0;
  region.max().array() += world.margin + 1.0;
  auto generated = World::generate(world, region, deriveSeed(seed, 0, RngStream::kWorld));
  if (!generated.ok()) return Status::Error(source + ": " + generated.status().message());
  return generated;
}

Expected<Scenario> Scenario::fromString(const std::string& yaml, const std::string& source,
                                        const std::string& base_dir) {
  auto cfg = ConfigNode::fromString(yaml, source);
  if (!cfg.ok()) return cfg.status();
  Scenario s;
  Status st = s.load(*cfg, base_dir);
  if (!st.ok()) return st;
  return s;
}

Expected<Scenario> Scenario::loadFile(const std::string& path) {
  auto cfg = ConfigNode::loadFile(path);
  if (!cfg.ok()) return cfg.status();
  const auto slash = path.find_last_of('/');
  const std::string base_dir = slash == std::string::npos ? "." : path.substr(0, slash);
  Scenario s;
  Status st = s.load(*cfg, base_dir);
  if (!st.ok()) return st;
  return s;
}

}  // namespace cvslam::sim
