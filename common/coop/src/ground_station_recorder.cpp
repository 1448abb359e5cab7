#include "cvslam/coop/ground_station_recorder.h"

#include <algorithm>
#include <filesystem>
#include <memory>

#include "cvslam/io/json_file.h"
#include "cvslam/io/run_writer.h"
#include "cvslam/slam/agent_run_recorder.h"

namespace cvslam::coop {

GroundStationRecorder::GroundStationRecorder() = default;
GroundStationRecorder::~GroundStationRecorder() = default;

Status GroundStationRecorder::open(const std::string& run_dir, const RunInfo& info) {
  dir_ = run_dir + "/ground_station";
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) return Status::Error(dir_ + ": cannot create folder: " + ec.message());
  RunInfo gs = info;
  gs.mode = "cc";
  return writeRunInfo(dir_, gs);
}

Status GroundStationRecorder::addStep(const CcTeamFilter& filter, const CcStepReport& report,
                                      const Vector9d* truth) {
  if (dir_.empty()) return Status::Error("GroundStationRecorder: not open");
  if (!report.accepted) return Status::Ok();
  auto it = agents_.find(report.agent_id);
  if (it == agents_.end()) {
    auto writer = std::make_unique<AgentRunWriter>();
    if (Status s = writer->open(dir_, report.agent_id); !s.ok()) return s;
    it = agents_.emplace(report.agent_id, std::move(writer)).first;
  }
  Expected<VehicleEstimate> e = filter.estimate(report.agent_id);
  if (!e.ok()) return e.status();
  const double t = static_cast<double>(e->t_us) * 1e-6;
  AgentRunWriter& w = *it->second;
  if (Status s = w.addState(t, e->x_v.head<9>(), e->P_v.topLeftCorner<9, 9>()); !s.ok()) return s;
  if (truth != nullptr)
    if (Status s = w.addTruth(t, *truth); !s.ok()) return s;
  FrameStats fs;
  fs.t = t;
  fs.time_ms = report.step_ms;
  fs.state_size = report.state_size;
  fs.landmarks = report.frame.landmarks_in_state;
  w.addFrame(fs);
  if (!have_time_) t_first_ = t;
  t_last_ = std::max(t_last_, t);
  have_time_ = true;
  return Status::Ok();
}

void GroundStationRecorder::addBytesReceived(const std::string& stream, int64_t bytes) {
  bytes_received_[stream] += bytes;
}

void GroundStationRecorder::addDropped(const std::string& reason, int agent_id, int64_t bytes) {
  ++dropped_[reason];
  if (agent_id > 0) ++dropped_per_agent_[agent_id][reason];
  if (bytes < 0) return;
  auto [it, fresh] = dropped_bytes_.try_emplace(reason, bytes, bytes);
  if (!fresh) {
    it->second.first = std::min(it->second.first, bytes);
    it->second.second = std::max(it->second.second, bytes);
  }
}

Status GroundStationRecorder::writeStats(const CcTeamFilter& filter) const {
  const CcTeamStatistics& st = filter.statistics();
  const TimeSummary steps = summariseTimes(st.step_ms);
  const double duration = have_time_ ? t_last_ - t_first_ : 0.0;
  Json root = Json::object();
  root["duration_s"] = duration;
  root["batches"] = st.batches;
  root["rejected_invalid"] = st.rejected_invalid;
  root["rejected_stale"] = st.rejected_stale;
  root["rejected_unknown_agent"] = st.rejected_unknown_agent;
  root["rejected_propagation"] = st.rejected_propagation;
  root["rejected_update"] = st.rejected_update;
  Json dropped = Json::object();
  for (const auto& [reason, n] : dropped_) dropped[reason] = n;
  root["dropped_per_reason"] = dropped;
  Json failed_bytes = Json::object();
  for (const auto& [reason, bytes] : dropped_bytes_) {
    Json b = Json::object();
    b["min"] = bytes.first;
    b["max"] = bytes.second;
    failed_bytes[reason] = b;
  }
  root["dropped_bytes_per_reason"] = failed_bytes;
  root["step_ms_median"] = steps.median_ms;
  root["step_ms_p95"] = steps.p95_ms;
  root["step_ms_max"] = steps.max_ms;
  root["step_ms_mean"] = steps.mean_ms;
  root["state_size_max"] = st.max_state_size;
  root["state_size_final"] = filter.state().size();
  root["vehicles"] = filter.vehicles();
  root["map_landmarks"] = filter.map().size();
  root["observations_accepted"] = st.filter.observations_accepted;
  root["observations_rejected"] = st.filter.observations_rejected;
  root["theta_reductions"] = st.filter.theta_reductions;
  Json agents = Json::object();
  for (const auto& [id, c] : st.agents) {
    Json a = Json::object();
    a["batches"] = c.batches;
    a["rejected"] = c.rejected;
    Json refused = Json::object();
    for (const auto& [key, n] : c.refused) refused[key] = n;
    a["refused_per_reason"] = refused;
    Json dropped_agent = Json::object();
    if (auto d = dropped_per_agent_.find(id); d != dropped_per_agent_.end())
      for (const auto& [reason, n] : d->second) dropped_agent[reason] = n;
    a["dropped_per_reason"] = dropped_agent;
    a["imu_gaps_bridged"] = c.imu_gaps_bridged;
    a["imu_gap_bridged_s"] = c.imu_gap_bridged_s;
    a["observations"] = c.observations;
    a["type1"] = c.type1;
    a["type2"] = c.type2;
    a["type3"] = c.type3;
    a["loop_closures"] = c.loop_closures;
    a["rendezvous"] = c.rendezvous;
    agents[std::to_string(id)] = a;
  }
  root["agents"] = agents;
  int64_t total = 0;
  Json streams = Json::object();
  for (const auto& [stream, bytes] : bytes_received_) {
    streams[stream] = bytes;
    total += bytes;
  }
  root["bytes_received"] = total;
  root["bytes_received_per_stream"] = streams;
  root["bytes_received_per_s"] = duration > 0.0 ? static_cast<double>(total) / duration : 0.0;
  return writeJsonFile(dir_ + "/stats.json", root);
}

Status GroundStationRecorder::flush(const CcTeamFilter& filter) {
  if (dir_.empty()) return Status::Error("GroundStationRecorder: not open");
  for (auto& [id, w] : agents_)
    if (Status s = w->flush(); !s.ok()) return s;
  return writeStats(filter);
}

Status GroundStationRecorder::close(const CcTeamFilter& filter, const LandmarkTruth& truth) {
  if (dir_.empty()) return Status::Error("GroundStationRecorder: not open");
  const std::vector<LandmarkRecord> records = landmarkRecords(filter.map(), truth);
  // The joint map: the ground station's, and every UAV's (the map its estimate belongs to).
  if (Status s = writeLandmarksFile(dir_ + "/landmarks.csv", records); !s.ok()) return s;
  for (auto& [id, w] : agents_)
    if (Status s = w->writeLandmarks(records); !s.ok()) return s;
  for (auto& [id, w] : agents_)
    if (Status s = w->close(); !s.ok()) return s;
  return writeStats(filter);
}

}  // namespace cvslam::coop
