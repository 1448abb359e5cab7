#include "cvslam/eval/run_evaluation.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>

#include "cvslam/io/config_node.h"
#include "cvslam/io/run_reader.h"
#include "table_cell.h"

namespace cvslam {

Status RunEvaluationOptions::load(const ConfigNode& node) {
  node.get("time_tolerance_s", time_tolerance_s);
  node.getEnum("alignment", alignment,
               {{"none", Alignment::kNone}, {"se3", Alignment::kSE3}, {"yaw", Alignment::kYaw}});
  node.get("rpe_segment_m", rpe_segment_m);
  node.get("co_window", co_window);
  node.check(time_tolerance_s >= 0.0, "time_tolerance_s", "must be >= 0");
  node.check(rpe_segment_m > 0.0, "rpe_segment_m", "must be > 0");
  node.check(co_window >= 1, "co_window", "must be >= 1");
  return node.status();
}

namespace {

std::vector<TumPose> posesOf(const std::vector<StateRecord>& states) {
  std::vector<TumPose> poses;
  poses.reserve(states.size());
  for (const auto& s : states) poses.push_back(tumPoseFromState(s.t, s.x));
  return poses;
}

}  // namespace

AgentEvaluation evaluateAgent(const AgentRun& run, const AgentTruth& truth,
                              const RunEvaluationOptions& options) {
  AgentEvaluation ev;
  ev.id = run.id;
  ev.landmarks = run.landmarks.size();
  ev.steps = run.trajectory.size();
  const auto note = [&](const std::string& what, const Status& why) {
    ev.notes.push_back(what + ": " + why.message());
  };

  if (truth.states.empty()) {
    ev.notes.push_back("no ground truth: ATE, RPE, NEES and co are null");
  } else {
    const std::vector<TumPose> true_poses = posesOf(truth.states);
    const AteOptions ate_options{options.time_tolerance_s, options.alignment};
    if (auto ate = absoluteTrajectoryError(run.trajectory, true_poses, ate_options); ate.ok()) {
      ev.ate_rmse_m = ate->rmse_m;
      ev.ate_max_m = ate->max_m;
      if (ate->vertical_flipped)
        ev.notes.push_back(
            "ate: yaw alignment found the vertical axes opposite (estimate turned "
            "by π about x, e.g. NED onto z-up)");
    } else
      note("ate", ate.status());
    if (run.ins_trajectory) {
      if (auto ins = absoluteTrajectoryError(*run.ins_trajectory, true_poses, ate_options);
          ins.ok())
        ev.ins_ate_rmse_m = ins->rmse_m;
      else
        note("ins_ate", ins.status());
    }
    const RpeOptions rpe_options{options.rpe_segment_m, options.time_tolerance_s};
    if (auto rpe = relativePoseError(run.trajectory, true_poses, rpe_options); rpe.ok())
      ev.rpe_m_per_10m = rpe->mean_m;
    else
      note("rpe", rpe.status());
    if (run.states.empty()) {
      ev.notes.push_back("no states.csv: NEES and co are null");
    } else if (options.alignment != Alignment::kNone) {
      // NEES and co compare states and covariances in the estimator's frame; an aligned
      // truth lives in another one (attitude and velocity included).
      ev.notes.push_back(
          "aligned evaluation: NEES and co are null (they need the truth in the "
          "estimator's frame)");
    } else {
      if (auto nees = normalisedEstimationErrorSquared(
              run.states, truth.states, options.time_tolerance_s, truth.has_velocity);
          nees.ok()) {
        ev.nees_mean = nees->mean;
        ev.nees_position_mean = nees->mean_position;
      } else {
        note("nees", nees.status());
      }
      ConsistencyOptions co_options;
      co_options.time_tolerance_s = options.time_tolerance_s;
      co_options.window = options.co_window;
      if (auto co = consistencyDegree(run.states, truth.states, co_options); co.ok())
        ev.consistency = std::move(*co);
      else
        note("co", co.status());
    }
  }

  if (auto lm = landmarkErrors(run.landmarks, truth.landmarks); lm.ok())
    ev.landmark_error = *lm;
  else if (!run.landmarks.empty())
    note("landmarks", lm.status());

  if (run.nis_dof_sum && *run.nis_dof_sum > 0)
    ev.nis_per_dof = *run.nis_sum / static_cast<double>(*run.nis_dof_sum);

  std::vector<double> frame_ms;
  for (const FrameStats& f : run.stats.frames) {
    frame_ms.push_back(f.time_ms);
    ev.max_state_size = std::max(ev.max_state_size.value_or(0), f.state_size);
  }
  if (!frame_ms.empty()) ev.frame_time_ms_median = median(frame_ms);
  if (!run.trajectory.empty()) ev.covered_s = run.trajectory.back().t - run.trajectory.front().t;
  if (run.stats.duration_s > 0.0)
    ev.bytes_sent_per_s = static_cast<double>(run.stats.bytes_sent) / run.stats.duration_s;
  return ev;
}

Expected<std::vector<AgentEvaluation>> evaluateRun(const std::string& run_dir,
                                                   const std::string& gt_dir,
                                                   const RunEvaluationOptions& options) {
  auto ids = listAgentIds(run_dir);
  if (!ids.ok()) return ids.status();
  std::vector<LandmarkRecord> gt_landmarks;
  if (!gt_dir.empty()) {
    auto lm = readGroundTruthLandmarks(gt_dir);
    if (!lm.ok()) return lm.status();
    gt_landmarks = std::move(*lm);
  }
  // A ground station's record (stats.json with per-UAV batch counts): what each UAV sent.
  std::map<int, long> sent;
  if (auto gs = readJsonFile(run_dir + "/stats.json");
      gs.ok() && gs->contains("agents") && (*gs)["agents"].is_object()) {
    for (const auto& [key, a] : (*gs)["agents"].items()) {
      if (!a.is_object() || !a.contains("batches") || !a.contains("rejected")) continue;
      long n = a["batches"].get<long>() + a["rejected"].get<long>();
      if (a.contains("dropped_per_reason") && a["dropped_per_reason"].is_object())
        for (const auto& [reason, d] : a["dropped_per_reason"].items()) n += d.get<long>();
      sent[std::atoi(key.c_str())] = n;
    }
  }
  std::vector<AgentEvaluation> out;
  for (int id : *ids) {
    auto run = readAgentRun(run_dir, id);
    if (!run.ok()) return run.status();
    AgentTruth truth;
    truth.landmarks = gt_landmarks;
    if (!gt_dir.empty()) {
      auto gt = readGroundTruth(gt_dir, id, &truth.has_velocity);
      if (!gt.ok()) return gt.status();
      truth.states = std::move(*gt);
    } else {
      truth.states = run->truth;
    }
    AgentEvaluation ev = evaluateAgent(*run, truth, options);
    if (auto it = sent.find(id); it != sent.end() && it->second > 0) {
      ev.coverage = static_cast<double>(ev.steps) / static_cast<double>(it->second);
      if (*ev.coverage < 0.95)
        ev.notes.push_back("coverage: the figures are over " + std::to_string(ev.steps) + " of " +
                           std::to_string(it->second) + " batches the UAV sent");
    } else if (!run->stats.frames.empty()) {
      ev.coverage = std::min(
          1.0, static_cast<double>(ev.steps) / static_cast<double>(run->stats.frames.size()));
    }
    out.push_back(std::move(ev));
  }
  return out;
}

namespace {

Json optionalNumber(const std::optional<double>& x) {
  return x ? Json(*x) : Json();
}

Json vector3(const Eigen::Vector3d& v) {
  return Json::array({v.x(), v.y(), v.z()});
}

/// One agent's member of the summary's "agents" object.
Json agentSummary(const AgentEvaluation& ev) {
  Json a = Json::object();
  a["ate_rmse_m"] = optionalNumber(ev.ate_rmse_m);
  a["ate_max_m"] = optionalNumber(ev.ate_max_m);
  a["ins_ate_rmse_m"] = optionalNumber(ev.ins_ate_rmse_m);
  a["rpe_m_per_10m"] = optionalNumber(ev.rpe_m_per_10m);
  a["nees_mean"] = optionalNumber(ev.nees_mean);
  a["nees_position_mean"] = optionalNumber(ev.nees_position_mean);
  a["nis_per_dof"] = optionalNumber(ev.nis_per_dof);
  a["max_state_size"] = ev.max_state_size ? Json(*ev.max_state_size) : Json();
  a["landmark_error_mean_m"] = ev.landmark_error ? vector3(ev.landmark_error->mean_m) : Json();
  a["landmark_error_std_m"] = ev.landmark_error ? vector3(ev.landmark_error->std_m) : Json();
  a["landmark_error_rms_m"] = ev.landmark_error ? Json(ev.landmark_error->rms_m) : Json();
  a["landmarks"] = ev.landmarks;
  a["landmarks_with_truth"] = ev.landmark_error ? ev.landmark_error->count : std::size_t{0};
  a["frame_time_ms_median"] = optionalNumber(ev.frame_time_ms_median);
  a["bytes_sent_per_s"] = optionalNumber(ev.bytes_sent_per_s);
  if (ev.consistency) {
    Json rco = Json::object(), sigma = Json::object(), true_sigma = Json::object();
    for (std::size_t s = 0; s < 9; ++s) {
      rco[kVehicleStateNames[s]] = ev.consistency->rco[s];  // +inf (never defined) → null
      sigma[kVehicleStateNames[s]] = ev.consistency->sigma_mean[s];
      true_sigma[kVehicleStateNames[s]] = ev.consistency->true_sigma_mean[s];
    }
    a["rco"] = std::move(rco);
    a["sigma_mean"] = std::move(sigma);
    a["true_sigma_mean"] = std::move(true_sigma);
  } else {
    a["rco"] = nullptr;
  }
  a["steps"] = ev.steps;
  a["coverage"] = optionalNumber(ev.coverage);
  a["covered_s"] = optionalNumber(ev.covered_s);
  a["notes"] = ev.notes;
  return a;
}

}  // namespace

Json summaryJson(const RunInfo& info, const std::vector<AgentEvaluation>& agents,
                 const RunEvaluationOptions& options) {
  Json root = Json::object();
  root["mode"] = info.mode.empty() ? Json() : Json(info.mode);
  root["filter"] = info.filter.empty() ? Json() : Json(info.filter);
  if (!info.map.empty()) root["map"] = info.map;
  root["alignment"] = alignmentName(options.alignment);
  Json all = Json::object();
  for (const AgentEvaluation& ev : agents) all[std::to_string(ev.id)] = agentSummary(ev);
  root["agents"] = std::move(all);
  return root;
}

std::string summaryTable(const std::vector<AgentEvaluation>& agents) {
  const auto cell = eval_detail::tableCell;
  std::string out;
  char line[512];
  std::snprintf(line, sizeof(line), "%-6s %10s %10s %10s %8s %9s %6s %14s %10s %12s %8s %8s\n",
                "agent", "ATE[m]", "INS ATE[m]", "RPE[m/10m]", "NEES", "min Rco", "state",
                "lm err rms[m]", "frame[ms]", "sent[B/s]", "NIS/dof", "cover[%]");
  out += line;
  for (const AgentEvaluation& ev : agents) {
    std::optional<double> rco;
    if (ev.consistency) {
      const double m = *std::min_element(ev.consistency->rco.begin(), ev.consistency->rco.end());
      if (std::isfinite(m)) rco = m;
    }
    std::optional<double> lm;
    if (ev.landmark_error) lm = ev.landmark_error->rms_m;
    std::optional<double> size;
    if (ev.max_state_size) size = *ev.max_state_size;
    std::optional<double> cover;
    if (ev.coverage) cover = 100.0 * *ev.coverage;
    std::snprintf(
        line, sizeof(line), "%-6d %10s %10s %10s %8s %9s %6s %14s %10s %12s %8s %8s\n", ev.id,
        cell(ev.ate_rmse_m, "%.4f").c_str(), cell(ev.ins_ate_rmse_m, "%.4f").c_str(),
        cell(ev.rpe_m_per_10m, "%.4f").c_str(), cell(ev.nees_mean, "%.2f").c_str(),
        cell(rco, "%.3f").c_str(), cell(size, "%.0f").c_str(), cell(lm, "%.4f").c_str(),
        cell(ev.frame_time_ms_median, "%.2f").c_str(), cell(ev.bytes_sent_per_s, "%.0f").c_str(),
        cell(ev.nis_per_dof, "%.2f").c_str(), cell(cover, "%.1f").c_str());
    out += line;
  }
  return out;
}

}  // namespace cvslam
