#pragma once
// Helpers for the agent process tests: ports, a short two-UAV scenario, evaluation of a run
// folder with cvslam_eval, and a listener for the agents' TEAM/SUMMARY heartbeats.
#include <condition_variable>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cvslam/io/json_file.h"
#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/coop_convert.h"
#include "cvslam/lcm/lcm_bus.h"
#include "cvslam/lcm/message_types.h"
#include "euroc_test_folder.h"
#include "replay/process_util.h"
#include "replay/small_scenario.h"

namespace cvslam::test {

/// A whole file as text ("" when it cannot be read).
inline std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// The two-UAV scenario of the cooperation tests.
inline std::string coopPair() {
  return std::string(CVSLAM_SOURCE_DIR) + "/config/scenarios/coop_pair.yaml";
}

/// The number after the first `label` in `text` (a process's report), -1 if absent.
inline long countAfter(const std::string& text, const std::string& label) {
  const auto pos = text.find(label);
  return pos == std::string::npos ? -1 : std::stol(text.substr(pos + label.size()));
}

/// Rows of a CSV whose columns may be text: the fields of each line after the header.
inline std::vector<std::vector<std::string>> csvRows(const std::string& path) {
  std::istringstream in(slurp(path));
  std::vector<std::vector<std::string>> rows;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::vector<std::string> fields;
    std::stringstream fs(line);
    for (std::string f; std::getline(fs, f, ',');) fields.push_back(f);
    rows.push_back(fields);
  }
  return rows;
}

/// Poses in a TUM trajectory file (0 when it cannot be read).
inline std::size_t poseCount(const std::string& tum_path) {
  std::ifstream tum(tum_path);
  std::size_t n = 0;
  for (std::string line; std::getline(tum, line);)
    if (!line.empty() && line[0] != '#') ++n;
  return n;
}

/// Poses of a TUM trajectory by their time text (the pose columns as written).
inline std::map<std::string, std::string> tumPoses(const std::string& tum_path) {
  std::map<std::string, std::string> poses;
  std::ifstream tum(tum_path);
  for (std::string line; std::getline(tum, line);) {
    if (line.empty() || line[0] == '#') continue;
    const auto space = line.find(' ');
    if (space != std::string::npos) poses[line.substr(0, space)] = line.substr(space + 1);
  }
  return poses;
}

/// The frames an agent in cc mode took from its own filter: frames_own of the last row of its
/// coop.csv (-1 when it cannot be read).
inline long ownFrames(const std::string& coop_csv) {
  std::ifstream f(coop_csv);
  std::string line, last;
  while (std::getline(f, line))
    if (!line.empty()) last = line;
  const auto comma = last.rfind(',');
  if (comma == std::string::npos) return -1;
  try {
    return std::stol(last.substr(comma + 1));
  } catch (const std::exception&) {
    return -1;
  }
}

/// cvslam_agent's command line for one UAV of `scenario` on `url`, recording into `out`,
/// exiting 3 s after the sensors fall silent.
inline std::vector<std::string> agentArgs(int id, const std::string& scenario,
                                          const std::string& url, const std::string& out,
                                          const std::string& mode = "single") {
  return {CVSLAM_AGENT_EXE,
          "--id",
          std::to_string(id),
          "--scenario",
          scenario,
          "--mode",
          mode,
          "--lcm-url",
          url,
          "--out",
          out,
          "--idle-exit",
          "3"};
}

inline std::string agentUrl(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
}

/// ATE RMSE per agent id of a run folder, by cvslam_eval.
inline std::map<int, double> ateOf(const std::string& run_dir, const std::string& log_prefix,
                                   const std::string& align = "none") {
  std::map<int, double> ate;
  std::string err;
  const std::string json_path = log_prefix + ".json";
  if (run({CVSLAM_EVAL_EXE, "--run", run_dir, "--summary-json", json_path, "--align", align},
          log_prefix, nullptr, &err) != 0)
    return ate;
  auto json = readJsonFile(json_path);
  if (!json.ok() || !json->contains("agents")) return ate;
  const Json& agents = json->at("agents");
  for (int id = 1; id <= 9; ++id) {
    const auto a = agents.find(std::to_string(id));
    if (a != agents.end() && a->contains("ate_rmse_m") && a->at("ate_rmse_m").is_number())
      ate[id] = a->at("ate_rmse_m").get<double>();
  }
  return ate;
}

/// Publishes a rogue peer's TEAM/SUMMARY (boot id 99, a vehicle covariance trace of 1 m²) at
/// dataset time `t_us`; false if it could not be encoded or sent.
inline bool publishRogueSummary(transport::LcmBus& bus, int id, int64_t seq, int64_t t_us,
                                int num_features, bool own_frame = false) {
  coop::CoopSummary s;
  s.header = {id, seq, t_us};
  s.boot_id = 99;
  s.num_features = num_features;
  s.vehicle_cov_trace = 1.0;
  s.own_frame = own_frame;
  auto m = transport::toMessage(s);
  return m.ok() && bus.publish(transport::channels::teamSummary(), *m).ok();
}

/// Records the boot ids and modes heard on TEAM/SUMMARY per agent.
class SummaryListener {
 public:
  explicit SummaryListener(const std::string& url) {
    transport::BusOptions o;
    o.url = url;
    auto bus = transport::LcmBus::create(o);
    if (!bus.ok()) return;
    bus_ = std::move(*bus);
    bus_->subscribe<cvslam::agent_summary_t>(transport::channels::teamSummary(),
                                             [this](const cvslam::agent_summary_t& m) {
                                               std::lock_guard<std::mutex> lock(mutex_);
                                               boot_ids_[m.header.agent_id].insert(m.boot_id);
                                               last_[m.header.agent_id] = m;
                                               ++heard_[m.header.agent_id];
                                               if (!m.channel.empty()) {
                                                 last_counted_[m.header.agent_id] = m;
                                                 ++counted_[m.header.agent_id];
                                               }
                                             });
    bus_->start();
  }
  bool ok() const { return bus_ != nullptr; }
  std::set<int64_t> bootIds(int id) {
    std::lock_guard<std::mutex> lock(mutex_);
    return boot_ids_[id];
  }
  /// The latest summary of agent `id` (default-constructed if none).
  cvslam::agent_summary_t last(int id) {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_[id];
  }
  /// The latest summary of agent `id` that carried its receive counters.
  cvslam::agent_summary_t lastCounted(int id) {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_counted_[id];
  }
  /// Summaries heard from agent `id`: all, and those that carried its receive counters.
  std::pair<int, int> summaryCounts(int id) {
    std::lock_guard<std::mutex> lock(mutex_);
    return {heard_[id], counted_[id]};
  }

 private:
  std::unique_ptr<transport::LcmBus> bus_;
  std::mutex mutex_;
  std::map<int, std::set<int64_t>> boot_ids_;
  std::map<int, cvslam::agent_summary_t> last_;
  std::map<int, cvslam::agent_summary_t> last_counted_;
  std::map<int, int> heard_, counted_;
};

/// The latest STATUS message of every process (UAV0 is the ground station), and a wait for a
/// condition on them.
class StatusListener {
 public:
  explicit StatusListener(const std::string& url) {
    transport::BusOptions o;
    o.url = url;
    auto bus = transport::LcmBus::create(o);
    if (!bus.ok()) return;
    bus_ = std::move(*bus);
    bus_->subscribe<cvslam::status_t>(transport::allAgentsPattern(transport::Stream::kStatus),
                                      [this](const cvslam::status_t& m) {
                                        std::lock_guard<std::mutex> lock(mutex_);
                                        last_[m.header.agent_id] = m.message;
                                        changed_.notify_all();
                                      });
    bus_->start();
  }
  bool ok() const { return bus_ != nullptr; }
  std::string last(int id) {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_[id];
  }
  /// Waits until `id`'s latest STATUS message contains `text`; false on timeout.
  bool waitFor(int id, const std::string& text, std::chrono::seconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, timeout,
                             [&] { return last_[id].find(text) != std::string::npos; });
  }

 private:
  std::unique_ptr<transport::LcmBus> bus_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<int, std::string> last_;
};

}  // namespace cvslam::test
