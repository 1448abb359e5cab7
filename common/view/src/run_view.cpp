#include "cvslam/view/run_view.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "cvslam/io/run_reader.h"

namespace cvslam::view {
namespace {

struct CoopRow {
  double t;
  std::string event;
  int peer;
};

// coop.csv of --mode dc (docs/run_format.md): t,event,peer,... ; other layouts (cc) have no
// peer-to-peer exchanges and give no rows.
std::vector<CoopRow> readCoopExchanges(const std::string& path) {
  std::vector<CoopRow> rows;
  std::ifstream f(path);
  std::string line;
  if (!std::getline(f, line) || line.rfind("t,event,peer", 0) != 0) return rows;
  while (std::getline(f, line)) {
    std::stringstream ss(line);
    std::string t, event, peer;
    if (!std::getline(ss, t, ',') || !std::getline(ss, event, ',') || !std::getline(ss, peer, ','))
      continue;
    try {
      rows.push_back({std::stod(t), event, std::stoi(peer)});
    } catch (const std::exception&) {
      continue;  // a torn last line of a run still being written
    }
  }
  return rows;
}

std::vector<ViewLandmark> viewLandmarks(const std::vector<LandmarkRecord>& records) {
  std::vector<ViewLandmark> out;
  out.reserve(records.size());
  for (const LandmarkRecord& r : records) {
    ViewLandmark l;
    l.p = r.p_LinN.cast<float>();
    l.std_m = static_cast<float>(std::sqrt(std::max(0.0, r.var.sum() / 3.0)));
    out.push_back(l);
  }
  return out;
}

}  // namespace

Expected<Json> runViewJson(const std::string& run_dir, const TeamViewOptions& options) {
  Expected<std::vector<int>> ids = listAgentIds(run_dir);
  if (!ids.ok()) return ids.status();
  TeamView view(options);
  double t0 = std::numeric_limits<double>::infinity(), t1 = -t0;
  for (int id : *ids) {
    Expected<AgentRun> run = readAgentRun(run_dir, id);
    if (!run.ok()) return run.status();
    int64_t coop_bytes = 0;
    for (const auto& [stream, n] : run->stats.bytes_sent_per_stream)
      if (stream == "cooperation") coop_bytes = n;
    std::optional<double> bytes_per_s;
    if (coop_bytes > 0 && run->stats.duration_s > 0.0)
      bytes_per_s = static_cast<double>(coop_bytes) / run->stats.duration_s;
    // Per-frame figures by time (stats.json frames).
    std::map<double, const FrameStats*> frames;
    for (const FrameStats& f : run->stats.frames) frames[f.t] = &f;
    // Estimates from states.csv (covariance), else the trajectory without one.
    std::vector<ViewEstimate> estimates;
    if (!run->states.empty()) {
      for (const StateRecord& s : run->states) {
        ViewEstimate e;
        e.t = s.t;
        e.p = s.x.head<3>();
        e.P = s.P.topLeftCorner<3, 3>();
        e.yaw = s.x(8);
        estimates.push_back(e);
      }
    } else {
      for (const TumPose& p : run->trajectory) {
        ViewEstimate e;
        e.t = p.t;
        e.p = p.p_BinN;
        const Eigen::Matrix3d R = p.q_BtoN.toRotationMatrix();
        e.yaw = std::atan2(R(1, 0), R(0, 0));
        estimates.push_back(e);
      }
    }
    // Truth and estimates in time order, so each estimate finds its truth (NEES).
    std::size_t k = 0;
    for (ViewEstimate& e : estimates) {
      while (k < run->truth.size() && run->truth[k].t <= e.t + options.truth_tolerance_s) {
        view.addTruth(id, run->truth[k].t, run->truth[k].x.head<3>());
        ++k;
      }
      e.agent_id = id;
      auto f = frames.lower_bound(e.t - 1e-6);
      if (f != frames.end() && std::abs(f->first - e.t) <= 1e-6) {
        if (f->second->landmarks >= 0) e.landmarks_active = f->second->landmarks;
        if (std::isfinite(f->second->latency_ms)) e.latency_ms = f->second->latency_ms;
      }
      e.bytes_per_s = bytes_per_s;
      view.addEstimate(e, 0.0);
      t0 = std::min(t0, e.t);
      t1 = std::max(t1, e.t);
    }
    for (; k < run->truth.size(); ++k)
      view.addTruth(id, run->truth[k].t, run->truth[k].x.head<3>());
    std::vector<ViewLandmark> map = viewLandmarks(run->landmarks);
    // The final map's counts: landmarks.csv holds the active and the archived ones.
    const int active = estimates.empty() ? 0 : std::max(estimates.back().landmarks_active, 0);
    view.setLandmarkCounts(id, active, std::max(0, static_cast<int>(map.size()) - active));
    view.setMap(id, t1, std::move(map));
    for (const CoopRow& r : readCoopExchanges(agentDir(run_dir, id) + "/coop.csv")) {
      if (r.event == "request_sent") view.addLink(id, r.peer, r.t, LinkKind::kRequest);
      if (r.event == "shared_sent") view.addLink(id, r.peer, r.t, LinkKind::kLandmarks);
    }
  }
  const std::string joint = run_dir + "/ground_station/landmarks.csv";
  if (std::filesystem::exists(joint)) {
    Expected<std::vector<LandmarkRecord>> lm = readLandmarks(joint);
    if (!lm.ok()) return lm.status();
    view.setJointMap(t1, viewLandmarks(*lm));
  }
  ViewCursor cursor;
  Json out = view.delta(cursor, 0.0);
  out["live"] = false;
  out["t0"] = std::isfinite(t0) ? t0 : 0.0;
  out["t1"] = std::isfinite(t1) ? t1 : 0.0;
  out["run"] = run_dir;
  Expected<RunInfo> info = readRunInfo(run_dir);
  if (info.ok()) {
    out["mode"] = info->mode;
    for (auto& [id, a] : out["agents"].items()) a["mode"] = info->mode;
  }
  return out;
}

}  // namespace cvslam::view
