#include "cvslam/view/team_view.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace cvslam::view {
namespace {

// JSON numbers at the precision a display needs: positions to the millimetre, everything
// else to four significant digits, so a delta stays small (nlohmann writes the shortest text
// that reads back the same double).
double mm(double x) {
  return std::round(x * 1e3) / 1e3;
}
double sig4(double x) {
  if (!std::isfinite(x) || x == 0.0) return x;
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", x);
  return std::strtod(text, nullptr);
}
Json optional(const std::optional<double>& v) {
  return v ? Json(sig4(*v)) : Json(nullptr);
}

Json landmarksJson(double t, const std::vector<ViewLandmark>& landmarks) {
  Json points = Json::array();
  for (const ViewLandmark& l : landmarks)
    points.push_back({mm(l.p.x()), mm(l.p.y()), mm(l.p.z()), sig4(l.std_m), l.active ? 1 : 0});
  return {{"t", t}, {"points", std::move(points)}};
}

}  // namespace

Status TeamViewOptions::load(const ConfigNode& node) {
  node.get("track_min_step_m", track_min_step_m);
  node.get("track_max_gap_s", track_max_gap_s);
  node.get("max_samples_per_uav", max_samples_per_uav);
  node.get("link_hold_s", link_hold_s);
  node.get("max_links", max_links);
  node.get("rate_window_s", rate_window_s);
  node.get("truth_tolerance_s", truth_tolerance_s);
  node.get("max_agents", max_agents);
  node.check(track_min_step_m >= 0.0, "track_min_step_m", "must be >= 0");
  node.check(track_max_gap_s > 0.0, "track_max_gap_s", "must be > 0");
  node.check(max_samples_per_uav >= 100, "max_samples_per_uav", "must be >= 100");
  node.check(link_hold_s > 0.0, "link_hold_s", "must be > 0");
  node.check(max_links >= 1, "max_links", "must be >= 1");
  node.check(rate_window_s > 0.0, "rate_window_s", "must be > 0");
  node.check(truth_tolerance_s >= 0.0, "truth_tolerance_s", "must be >= 0");
  node.check(max_agents >= 1, "max_agents", "must be >= 1");
  return node.status();
}

const char* linkKindName(LinkKind kind) {
  switch (kind) {
    case LinkKind::kRequest:
      return "request";
    case LinkKind::kLandmarks:
      return "landmarks";
    case LinkKind::kObservations:
      return "observations";
  }
  return "";
}

TeamView::TeamView(TeamViewOptions options) : o_(options) {}

TeamView::Agent* TeamView::agent(int agent_id) {
  auto it = agents_.find(agent_id);
  if (it != agents_.end()) return &it->second;
  if (agent_id < 1 || static_cast<int>(agents_.size()) >= o_.max_agents) {
    ++ignored_agents_;
    return nullptr;
  }
  return &agents_[agent_id];
}

template <typename T>
void TeamView::bound(std::vector<T>& v, int64_t* epoch) {
  if (static_cast<int>(v.size()) < o_.max_samples_per_uav) return;
  // Thin the older half (every other sample) so the whole flight stays drawn.
  const std::size_t half = v.size() / 2;
  std::vector<T> kept;
  kept.reserve(v.size());
  for (std::size_t i = 0; i < half; i += 2) kept.push_back(v[i]);
  kept.insert(kept.end(), v.begin() + static_cast<std::ptrdiff_t>(half), v.end());
  v.swap(kept);
  if (epoch) ++*epoch;
}

std::optional<double> TeamView::bytesPerSecond(const Agent& a, double wall_s) const {
  if (a.traffic.empty()) return std::nullopt;
  std::size_t bytes = 0;
  for (const auto& [wall, n] : a.traffic)
    if (wall >= wall_s - o_.rate_window_s) bytes += n;
  return static_cast<double>(bytes) / o_.rate_window_s;
}

void TeamView::addEstimate(const ViewEstimate& e, double wall_s) {
  Agent* a = agent(e.agent_id);
  if (a == nullptr) return;
  latest_t_ = std::max(latest_t_, e.t);
  Sample s{e.t,
           e.p,
           e.P(0, 0),
           e.P(0, 1),
           e.P(1, 1),
           std::sqrt(std::max(0.0, e.P.trace())),
           e.yaw,
           std::nullopt,
           std::nullopt,
           std::nullopt,
           e.landmarks_active};
  // Position NEES against the truth nearest in time (3 dof).
  const std::pair<double, Eigen::Vector3d>* truth = nullptr;
  for (const auto& tr : a->recent_truth) {
    if (std::abs(tr.first - e.t) <= o_.truth_tolerance_s &&
        (truth == nullptr || std::abs(tr.first - e.t) < std::abs(truth->first - e.t)))
      truth = &tr;
  }
  if (truth != nullptr) {
    Eigen::LDLT<Eigen::Matrix3d> ldlt(e.P);
    if (ldlt.info() == Eigen::Success && ldlt.isPositive() && ldlt.vectorD().minCoeff() > 0.0) {
      const Eigen::Vector3d err = e.p - truth->second;
      s.nees = err.dot(ldlt.solve(err));
    }
  }
  while (!a->frame_arrivals.empty() && a->frame_arrivals.front().first < e.t - 1e-7)
    a->frame_arrivals.pop_front();
  if (!a->frame_arrivals.empty() && std::abs(a->frame_arrivals.front().first - e.t) <= 1e-6) {
    s.latency_ms = std::max(0.0, (wall_s - a->frame_arrivals.front().second) * 1e3);
    a->frame_arrivals.pop_front();
  }
  s.bytes_per_s = bytesPerSecond(*a, wall_s);
  if (e.latency_ms) s.latency_ms = e.latency_ms;
  if (e.bytes_per_s) s.bytes_per_s = e.bytes_per_s;
  if (e.landmarks_active >= 0) a->landmarks_active = e.landmarks_active;
  if (e.landmarks_archived >= 0) a->landmarks_archived = e.landmarks_archived;
  const bool moved = a->samples.empty() ||
                     (e.p - a->samples.back().p).norm() >= o_.track_min_step_m ||
                     e.t - a->last_kept_t >= o_.track_max_gap_s || e.t < a->last_kept_t;
  a->last = s;
  if (moved) {
    bound(a->samples, &a->samples_epoch);
    a->samples.push_back(s);
    a->last_kept_t = e.t;
  }
}

void TeamView::addGroundStationEstimate(const ViewEstimate& e) {
  Agent* a = agent(e.agent_id);
  if (a == nullptr) return;
  a->gs = e;
}

void TeamView::addTruth(int agent_id, double t, const Eigen::Vector3d& p) {
  Agent* a = agent(agent_id);
  if (a == nullptr) return;
  a->recent_truth.emplace_back(t, p);
  while (a->recent_truth.size() > 1 && a->recent_truth.front().first < t - 1.0)
    a->recent_truth.pop_front();
  if (a->truth.empty() || (p - a->truth.back().second).norm() >= o_.track_min_step_m ||
      t - a->truth.back().first >= o_.track_max_gap_s || t < a->truth.back().first) {
    bound(a->truth, &a->samples_epoch);
    a->truth.emplace_back(t, p);
  }
}

void TeamView::setMap(int agent_id, double t, std::vector<ViewLandmark> landmarks) {
  Agent* a = agent(agent_id);
  if (a == nullptr) return;
  a->map = std::move(landmarks);
  a->map_t = t;
  ++a->map_version;
}

void TeamView::setJointMap(double t, std::vector<ViewLandmark> landmarks) {
  joint_map_ = std::move(landmarks);
  joint_map_t_ = t;
  ++joint_map_version_;
}

void TeamView::addFrameArrival(int agent_id, double t, double wall_s) {
  Agent* a = agent(agent_id);
  if (a == nullptr) return;
  a->frame_arrivals.emplace_back(t, wall_s);
  // A frame whose estimate never comes (dropped by the agent) must not pile up.
  constexpr std::size_t kMaxPending = 256;
  while (a->frame_arrivals.size() > kMaxPending) a->frame_arrivals.pop_front();
}

void TeamView::addLink(int from, int to, double t, LinkKind kind) {
  if (agent(from) == nullptr) return;
  links_.push_back({from, to, t, kind});
  ++links_total_;
  while (static_cast<int>(links_.size()) > o_.max_links) links_.pop_front();
}

void TeamView::addTraffic(int agent_id, std::size_t bytes, double wall_s) {
  Agent* a = agent(agent_id);
  if (a == nullptr) return;
  a->traffic.emplace_back(wall_s, bytes);
  a->bytes_total += static_cast<int64_t>(bytes);
  while (!a->traffic.empty() && a->traffic.front().first < wall_s - o_.rate_window_s)
    a->traffic.pop_front();
}

void TeamView::setAgentInfo(int agent_id, const std::string& mode, int64_t boot_id) {
  Agent* a = agent(agent_id);
  if (a == nullptr) return;
  a->mode = mode;
  a->boot_id = boot_id;
}

void TeamView::setLandmarkCounts(int agent_id, int active, int archived) {
  Agent* a = agent(agent_id);
  if (a == nullptr) return;
  a->landmarks_active = active;
  a->landmarks_archived = archived;
}

void TeamView::setStatus(int process_id, int health, const std::string& message) {
  if (process_id == 0) {
    gs_status_ = std::make_pair(health, message);
    return;
  }
  Agent* a = agent(process_id);
  if (a == nullptr) return;
  a->health = health;
  a->status = message;
}

void TeamView::countMalformed(const std::string& channel) {
  ++malformed_[channel];
  ++malformed_total_;
}

Json TeamView::delta(ViewCursor& c, double wall_s) const {
  const bool reset = !c.started;
  c.started = true;
  Json agents = Json::object();
  for (const auto& [id, a] : agents_) {
    Json j = {{"mode", a.mode},
              {"landmarks_active", a.landmarks_active},
              {"landmarks_archived", a.landmarks_archived},
              {"bytes_total", a.bytes_total},
              {"bytes_per_s", optional(bytesPerSecond(a, wall_s))},
              {"health", a.health},
              {"status", a.status}};
    // Samples (and truth) from where this client stopped; from 0 after old ones were thinned.
    const bool restart = reset || c.samples_epoch[id] != a.samples_epoch;
    c.samples_epoch[id] = a.samples_epoch;
    std::size_t& sent = c.samples[id];
    std::size_t& sent_truth = c.truth[id];
    if (restart) sent = sent_truth = 0;
    Json samples = Json::array();
    for (std::size_t i = sent; i < a.samples.size(); ++i) {
      const Sample& s = a.samples[i];
      samples.push_back({s.t, mm(s.p.x()), mm(s.p.y()), mm(s.p.z()), sig4(s.cxx), sig4(s.cxy),
                         sig4(s.cyy), sig4(s.sigma), sig4(s.yaw), optional(s.nees),
                         optional(s.latency_ms), optional(s.bytes_per_s), s.landmarks_active});
    }
    j["samples_from"] = sent;
    j["samples"] = std::move(samples);
    sent = a.samples.size();
    Json truth = Json::array();
    for (std::size_t i = sent_truth; i < a.truth.size(); ++i) {
      const auto& [t, p] = a.truth[i];
      truth.push_back({t, mm(p.x()), mm(p.y()), mm(p.z())});
    }
    j["truth_from"] = sent_truth;
    j["truth"] = std::move(truth);
    sent_truth = a.truth.size();
    if (a.last) {
      const Sample& s = *a.last;
      j["now"] = {s.t,         mm(s.p.x()), mm(s.p.y()),   mm(s.p.z()), sig4(s.cxx),
                  sig4(s.cxy), sig4(s.cyy), sig4(s.sigma), sig4(s.yaw)};
    }
    int64_t& map_sent = c.map_version[id];
    if (reset || map_sent != a.map_version) {
      j["map"] = landmarksJson(a.map_t, a.map);
      map_sent = a.map_version;
    }
    if (a.gs) {
      const ViewEstimate& g = *a.gs;
      j["gs"] = {g.t,
                 mm(g.p.x()),
                 mm(g.p.y()),
                 mm(g.p.z()),
                 sig4(g.P(0, 0)),
                 sig4(g.P(0, 1)),
                 sig4(g.P(1, 1))};
    }
    agents[std::to_string(id)] = std::move(j);
  }
  // Links from this client's last one (those forgotten meanwhile are skipped).
  const int64_t first_kept = links_total_ - static_cast<int64_t>(links_.size());
  const int64_t from = std::max(reset ? 0 : c.links, first_kept);
  Json links = Json::array();
  for (int64_t k = from; k < links_total_; ++k) {
    const Link& l = links_[static_cast<std::size_t>(k - first_kept)];
    links.push_back({l.t, l.from, l.to, linkKindName(l.kind)});
  }
  c.links = links_total_;
  Json out = {{"reset", reset},
              {"live", true},
              {"t", latest_t_},
              {"link_hold_s", o_.link_hold_s},
              {"messages", messages_},
              {"malformed", malformed_total_},
              {"malformed_by_channel", malformed_},
              {"ignored_agents", ignored_agents_},
              {"agents", std::move(agents)},
              {"links", std::move(links)}};
  if (gs_status_)
    out["gs_status"] = {{"health", gs_status_->first}, {"message", gs_status_->second}};
  if (reset || c.joint_map_version != joint_map_version_) {
    if (joint_map_version_ > 0) out["joint_map"] = landmarksJson(joint_map_t_, joint_map_);
    c.joint_map_version = joint_map_version_;
  }
  return out;
}

}  // namespace cvslam::view
