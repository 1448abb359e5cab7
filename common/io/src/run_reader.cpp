#include "cvslam/io/run_reader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "cvslam/geometry/euler.h"
#include "cvslam/io/csv_table.h"
#include "cvslam/io/json_file.h"

namespace cvslam {
namespace fs = std::filesystem;

Expected<std::vector<int>> listAgentIds(const std::string& run_dir) {
  std::error_code ec;
  if (!fs::is_directory(run_dir, ec)) return Status::Error(run_dir + ": no such run folder");
  std::vector<int> ids;
  for (const auto& entry : fs::directory_iterator(run_dir, ec)) {
    if (!entry.is_directory()) continue;
    const std::string name = entry.path().filename().string();
    const std::string prefix = "agent_";
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.empty() || !std::all_of(digits.begin(), digits.end(), ::isdigit)) continue;
    ids.push_back(std::stoi(digits));
  }
  if (ids.empty()) return Status::Error(run_dir + ": no agent_<id> folders");
  std::sort(ids.begin(), ids.end());
  return ids;
}

Expected<RunInfo> readRunInfo(const std::string& run_dir) {
  RunInfo info;
  const std::string path = run_dir + "/run.json";
  if (!fs::exists(path)) return info;
  auto json = readJsonFile(path);
  if (!json.ok()) return json.status();
  if (!json->is_object()) return Status::Error(path + ": expected a JSON object");
  const auto str = [&](const char* key, std::string& out) {
    if (const auto j = json->find(key); j != json->end() && j->is_string())
      out = j->get<std::string>();
  };
  str("mode", info.mode);
  str("filter", info.filter);
  str("map", info.map);
  str("scenario", info.scenario);
  str("sensing", info.sensing);
  str("world", info.world);
  str("pixel_noise", info.pixel_noise);
  str("config", info.config);
  str("program", info.program);
  str("commit", info.commit);
  if (const auto j = json->find("seed"); j != json->end() && j->is_number_unsigned())
    info.seed = j->get<uint64_t>();
  if (const auto j = json->find("duration_s"); j != json->end() && j->is_number())
    info.duration_s = j->get<double>();
  if (const auto j = json->find("linearised_at_truth"); j != json->end() && j->is_boolean())
    info.linearised_at_truth = j->get<bool>();
  if (const auto j = json->find("agents"); j != json->end() && j->is_array()) {
    for (const auto& id : *j)
      if (id.is_number_integer()) info.agents.push_back(id.get<int>());
  }
  if (const auto j = json->find("frames_in_world"); j != json->end()) {
    const Status malformed =
        Status::Error(path + ": frames_in_world: expected {\"<id>\": [t_N, t_E, t_D, yaw], ...}");
    if (!j->is_object()) return malformed;
    for (const auto& [key, f] : j->items()) {
      if (key.empty() || !std::all_of(key.begin(), key.end(), ::isdigit) || key.size() > 9 ||
          !f.is_array() || f.size() != 4)
        return malformed;
      Eigen::Vector4d x;
      for (int i = 0; i < 4; ++i) {
        if (!f[i].is_number() || !std::isfinite(f[i].get<double>())) return malformed;
        x(i) = f[i].get<double>();
      }
      info.frames_in_world[std::stoi(key)] = x;
    }
  }
  return info;
}

Expected<std::optional<TeamTrajectory>> readTeamTrajectory(const std::string& path) {
  if (!fs::exists(path)) return std::optional<TeamTrajectory>();
  std::ifstream in(path);
  std::string first;
  std::getline(in, first);
  const std::string prefix = std::string("# ") + kTeamFramePrefix;
  const std::string digits = first.rfind(prefix, 0) == 0 ? first.substr(prefix.size()) : "";
  if (digits.empty() || digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), ::isdigit))
    return Status::Error(path + ":1: expected '" + prefix + "<id>' (the team frame)");
  auto poses = readTumTrajectory(path);
  if (!poses.ok()) return poses.status();
  return std::optional<TeamTrajectory>(TeamTrajectory{std::stoi(digits), std::move(*poses)});
}

Expected<std::vector<StateRecord>> readStateTable(const std::string& path, bool* full_covariance) {
  std::vector<std::string> required = {"t"};
  for (const char* n : kVehicleStateNames) required.emplace_back(n);
  auto table = readCsvTable(path, required);
  if (!table.ok()) return table.status();
  int x_col[9], var_col[9];
  for (int i = 0; i < 9; ++i) {
    x_col[i] = table->column(kVehicleStateNames[i]);
    var_col[i] = table->column(std::string("var_") + kVehicleStateNames[i]);
  }
  bool full = false;
  int cov_col[9][9];
  for (int i = 0; i < 9; ++i) {
    for (int j = i + 1; j < 9; ++j) {
      cov_col[i][j] = table->column("cov_" + std::to_string(i) + "_" + std::to_string(j));
      full = full || cov_col[i][j] >= 0;
    }
  }
  const int t_col = table->column("t");
  std::vector<StateRecord> out;
  out.reserve(table->rows.size());
  for (std::size_t r = 0; r < table->rows.size(); ++r) {
    const std::vector<double>& row = table->rows[r];
    StateRecord s;
    s.t = row[t_col];
    for (int i = 0; i < 9; ++i) {
      s.x(i) = row[x_col[i]];
      if (var_col[i] >= 0) s.P(i, i) = row[var_col[i]];
      for (int j = i + 1; j < 9; ++j)
        if (cov_col[i][j] >= 0) s.P(i, j) = s.P(j, i) = row[cov_col[i][j]];
    }
    if (!std::isfinite(s.t) || !s.x.allFinite())
      return Status::Error(table->where(r) + ": non-finite time or state");
    if (!out.empty() && !(s.t > out.back().t))
      return Status::Error(table->where(r) + ": time not after the previous row");
    out.push_back(s);
  }
  if (full_covariance) *full_covariance = full;
  return out;
}

Expected<std::vector<LandmarkRecord>> readLandmarks(const std::string& path) {
  auto table = readCsvTable(path, {"id", "x", "y", "z"});
  if (!table.ok()) return table.status();
  const char* axes[3] = {"x", "y", "z"};
  int p_col[3], var_col[3], true_col[3];
  for (int i = 0; i < 3; ++i) {
    p_col[i] = table->column(axes[i]);
    var_col[i] = table->column(std::string("var_") + axes[i]);
    true_col[i] = table->column(std::string("true_") + axes[i]);
  }
  std::vector<LandmarkRecord> out;
  for (std::size_t r = 0; r < table->rows.size(); ++r) {
    const std::vector<double>& row = table->rows[r];
    LandmarkRecord l;
    l.id = static_cast<int64_t>(row[table->column("id")]);
    Eigen::Vector3d truth;
    bool has_truth = true;
    for (int i = 0; i < 3; ++i) {
      l.p_LinN(i) = row[p_col[i]];
      l.var(i) = var_col[i] >= 0 ? row[var_col[i]] : std::nan("");
      truth(i) = true_col[i] >= 0 ? row[true_col[i]] : std::nan("");
      has_truth = has_truth && std::isfinite(truth(i));
    }
    if (!l.p_LinN.allFinite()) return Status::Error(table->where(r) + ": non-finite position");
    if (has_truth) l.truth = truth;
    out.push_back(l);
  }
  return out;
}

Expected<RunStats> readRunStats(const std::string& path) {
  auto json = readJsonFile(path);
  if (!json.ok()) return json.status();
  if (!json->is_object()) return Status::Error(path + ": expected a JSON object");
  RunStats s;
  const auto number = [&](const Json& obj, const char* key, double fallback) {
    const auto j = obj.find(key);
    return j != obj.end() && j->is_number() ? j->get<double>() : fallback;
  };
  s.duration_s = number(*json, "duration_s", 0.0);
  s.bytes_sent = static_cast<int64_t>(number(*json, "bytes_sent", 0.0));
  s.bytes_received = static_cast<int64_t>(number(*json, "bytes_received", 0.0));
  const auto frames_it = json->find("frames");
  if (frames_it == json->end()) return s;
  const Json& frames = *frames_it;
  if (!frames.is_object()) return Status::Error(path + ": 'frames' must be an object of arrays");
  const auto t = frames.find("t_s");
  const std::size_t n = t != frames.end() && t->is_array() ? t->size() : 0;
  s.frames.resize(n);
  const auto column = [&](const char* key, auto setter) -> Status {
    const auto a = frames.find(key);
    if (a == frames.end()) return Status::Ok();
    if (!a->is_array() || a->size() != n)
      return Status::Error(path + ": frames." + key + " must be an array as long as frames.t_s");
    for (std::size_t i = 0; i < n; ++i) {
      const Json& v = (*a)[i];
      if (!v.is_number() && !v.is_null())
        return Status::Error(path + ": frames." + key + "[" + std::to_string(i) +
                             "] is not a number");
      setter(s.frames[i], v.is_number() ? v.get<double>() : std::nan(""));
    }
    return Status::Ok();
  };
  Status st = column("t_s", [](FrameStats& f, double x) { f.t = x; });
  if (st.ok()) st = column("time_ms", [](FrameStats& f, double x) { f.time_ms = x; });
  if (st.ok())
    st = column("state_size", [](FrameStats& f, double x) { f.state_size = static_cast<int>(x); });
  if (st.ok())
    st = column("landmarks", [](FrameStats& f, double x) {
      f.landmarks = std::isfinite(x) ? static_cast<int>(x) : -1;
    });
  if (st.ok())
    st = column("landmark_sigma_mean_m",
                [](FrameStats& f, double x) { f.landmark_sigma_mean_m = x; });
  if (!st.ok()) return st;
  return s;
}

Expected<AgentRun> readAgentRun(const std::string& run_dir, int agent_id) {
  AgentRun run;
  run.id = agent_id;
  run.dir = agentDir(run_dir, agent_id);
  if (!fs::is_directory(run.dir)) return Status::Error(run.dir + ": no such agent folder");
  auto traj = readTumTrajectory(run.dir + "/trajectory.tum");
  if (!traj.ok()) return traj.status();
  run.trajectory = std::move(*traj);
  if (fs::exists(run.dir + "/ins_trajectory.tum")) {
    auto ins = readTumTrajectory(run.dir + "/ins_trajectory.tum");
    if (!ins.ok()) return ins.status();
    run.ins_trajectory = std::move(*ins);
  }
  auto team = readTeamTrajectory(run.dir + "/trajectory_team.tum");
  if (!team.ok()) return team.status();
  run.team = std::move(*team);
  if (fs::exists(run.dir + "/states.csv")) {
    auto states = readStateTable(run.dir + "/states.csv", &run.states_full_covariance);
    if (!states.ok()) return states.status();
    run.states = std::move(*states);
  }
  if (fs::exists(run.dir + "/truth.csv")) {
    auto truth = readStateTable(run.dir + "/truth.csv");
    if (!truth.ok()) return truth.status();
    run.truth = std::move(*truth);
  }
  auto landmarks = readLandmarks(run.dir + "/landmarks.csv");
  if (!landmarks.ok()) return landmarks.status();
  run.landmarks = std::move(*landmarks);
  auto stats = readRunStats(run.dir + "/stats.json");
  if (!stats.ok()) return stats.status();
  run.stats = std::move(*stats);
  if (fs::exists(run.dir + "/events.csv")) {
    auto events = readCsvTable(run.dir + "/events.csv");
    if (!events.ok()) return events.status();
    const int nis = events->column("nis"), dof = events->column("nis_dof");
    if (nis >= 0 && dof >= 0) {  // older runs' events.csv has neither column
      double nis_sum = 0.0;
      long dof_sum = 0;
      for (std::size_t r = 0; r < events->rows.size(); ++r) {
        const std::vector<double>& row = events->rows[r];
        if (!(row[nis] >= 0.0) || !(row[dof] >= 0.0))
          return Status::Error(events->where(r) + ": nis and nis_dof must be finite and ≥ 0");
        nis_sum += row[nis];
        dof_sum += static_cast<long>(row[dof]);
      }
      run.nis_sum = nis_sum;
      run.nis_dof_sum = dof_sum;
    }
  }
  return run;
}

namespace {

/// EuRoC ground truth: timestamp [ns], p_RS_R, q_RS (w x y z), v_RS_R, biases. The world
/// frame R is taken as N (our datasets are written in the shared NED frame); q_RS = q_BtoN.
Expected<std::vector<StateRecord>> readEurocGroundTruth(const std::string& path) {
  auto table = readCsvTable(path);
  if (!table.ok()) return table.status();
  if (table->header.size() < 11)
    return Status::Error(path + ": expected EuRoC ground truth with at least 11 columns");
  std::vector<StateRecord> out;
  for (std::size_t r = 0; r < table->rows.size(); ++r) {
    const std::vector<double>& row = table->rows[r];
    StateRecord s;
    s.t = row[0] * 1e-9;
    const Eigen::Quaterniond q_BtoN(row[4], row[5], row[6], row[7]);
    if (q_BtoN.norm() < 1e-6) return Status::Error(table->where(r) + ": zero quaternion");
    const Eigen::Matrix3d R_NtoB = q_BtoN.normalized().toRotationMatrix().transpose();
    s.x.head<3>() << row[1], row[2], row[3];
    s.x.segment<3>(3) = R_NtoB * Eigen::Vector3d(row[8], row[9], row[10]);
    s.x.tail<3>() = eulerFromRotationNavToBody(R_NtoB);
    if (!out.empty() && !(s.t > out.back().t))
      return Status::Error(table->where(r) + ": time not after the previous row");
    out.push_back(s);
  }
  return out;
}

}  // namespace

Expected<std::vector<StateRecord>> readGroundTruth(const std::string& gt_dir, int agent_id,
                                                   bool* has_velocity) {
  if (!fs::is_directory(gt_dir)) return Status::Error(gt_dir + ": no such ground-truth folder");
  const std::string agent = agentDir(gt_dir, agent_id);
  if (has_velocity) *has_velocity = true;
  if (fs::exists(agent + "/truth.csv")) return readStateTable(agent + "/truth.csv");
  if (fs::exists(agent + "/trajectory.tum")) {
    auto tum = readTumTrajectory(agent + "/trajectory.tum");
    if (!tum.ok()) return tum.status();
    std::vector<StateRecord> out;
    for (const TumPose& p : *tum) {
      StateRecord s;
      s.t = p.t;
      s.x.head<3>() = p.p_BinN;
      s.x.tail<3>() = eulerFromRotationNavToBody(p.q_BtoN.toRotationMatrix().transpose());
      out.push_back(s);
    }
    if (has_velocity) *has_velocity = false;
    return out;
  }
  const std::string id = std::to_string(agent_id);
  for (const std::string& name : {"agent_" + id, "uav" + id, "UAV" + id, id}) {
    const std::string path = gt_dir + "/" + name + "/mav0/state_groundtruth_estimate0/data.csv";
    if (fs::exists(path)) return readEurocGroundTruth(path);
  }
  // A single-vehicle EuRoC dataset folder (GT/mav0/...) serves whichever agent flew it.
  const std::string single = gt_dir + "/mav0/state_groundtruth_estimate0/data.csv";
  if (fs::exists(single)) return readEurocGroundTruth(single);
  return Status::Error(gt_dir + ": no ground truth for agent " + id + " (looked for agent_" + id +
                       "/truth.csv, agent_" + id +
                       "/trajectory.tum, [<agent>/]mav0/state_groundtruth_estimate0/data.csv)");
}

Expected<std::vector<LandmarkRecord>> readGroundTruthLandmarks(const std::string& gt_dir) {
  const std::string path = gt_dir + "/landmarks.csv";
  if (!fs::exists(path)) return std::vector<LandmarkRecord>{};
  return readLandmarks(path);
}

}  // namespace cvslam
