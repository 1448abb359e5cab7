#include "cvslam/eval/team_evaluation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>

#include "cvslam/eval/metrics.h"
#include "cvslam/io/run_reader.h"
#include "cvslam/merge/frame_relation.h"
#include "table_cell.h"

namespace cvslam {
namespace {

using merge::FrameRelation;
using Vector4d = FrameRelation::Vector4d;

/// run.json's frame of agent `id` in the world; zero (the world itself) when not listed.
Vector4d frameOf(const RunInfo& info, int id) {
  const auto it = info.frames_in_world.find(id);
  return it == info.frames_in_world.end() ? Vector4d::Zero() : it->second;
}

/// The frame [t, ψ] (p_world = R_z(ψ) p + t) as the relation "this frame → world".
FrameRelation inWorld(const Vector4d& frame) {
  FrameRelation r;
  r.x = frame;
  return r;
}

/// One row of relations.csv with a candidate (coop_log.h writes it).
struct RelationRow {
  double t = 0.0;
  int peer = 0;
  std::string verdict;
  FrameRelation candidate;
};

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  for (std::string f; std::getline(in, f, ',');) fields.push_back(f);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

Expected<std::vector<RelationRow>> readRelations(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open");
  std::string line;
  if (!std::getline(in, line)) return Status::Error(path + ": empty (no header)");
  const std::vector<std::string> header = splitCsv(line);
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < header.size(); ++i) col[header[i]] = i;
  static const char* kNumbers[] = {"t",   "peer", "t_n", "t_e", "t_d", "yaw", "p00", "p01",
                                   "p02", "p03",  "p11", "p12", "p13", "p22", "p23", "p33"};
  for (const char* name : kNumbers)
    if (!col.count(name)) return Status::Error(path + ": no column '" + name + "'");
  if (!col.count("verdict")) return Status::Error(path + ": no column 'verdict'");
  std::vector<RelationRow> rows;
  for (int line_no = 2; std::getline(in, line); ++line_no) {
    if (line.empty()) continue;
    const std::vector<std::string> f = splitCsv(line);
    const std::string at = path + ":" + std::to_string(line_no) + ": ";
    if (f.size() != header.size())
      return Status::Error(at + "expected " + std::to_string(header.size()) + " fields, got " +
                           std::to_string(f.size()));
    std::map<std::string, double> v;
    for (const char* name : kNumbers) {
      const std::string& text = f[col[name]];
      char* end = nullptr;
      const double x = std::strtod(text.c_str(), &end);
      if (text.empty() || *end != '\0' || !std::isfinite(x))
        return Status::Error(at + name + ": not a finite number: '" + text + "'");
      v[name] = x;
    }
    RelationRow r;
    r.t = v["t"];
    r.peer = static_cast<int>(v["peer"]);
    r.verdict = f[col["verdict"]];
    r.candidate.x << v["t_n"], v["t_e"], v["t_d"], v["yaw"];
    const char* upper[4][4] = {{"p00", "p01", "p02", "p03"},
                               {"p01", "p11", "p12", "p13"},
                               {"p02", "p12", "p22", "p23"},
                               {"p03", "p13", "p23", "p33"}};
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) r.candidate.P(i, j) = v[upper[i][j]];
    rows.push_back(r);
  }
  return rows;
}

/// Every candidate against the true relation of the peer's frame in the own frame.
RelationCheck checkRelations(const std::vector<RelationRow>& rows, const RunInfo& info, int id,
                             const TeamEvaluationOptions& options) {
  RelationCheck c;
  std::map<int, double> first_adoption;
  const FrameRelation own_in_world = inWorld(frameOf(info, id));
  for (const RelationRow& r : rows) {
    if (r.verdict == "failed") {
      ++c.failed;
      continue;
    }
    ++c.verified;
    const FrameRelation truth = own_in_world.inverse().compose(inWorld(frameOf(info, r.peer)));
    const Vector4d d = merge::relationDifference(r.candidate.x, truth.x);
    const double nees = d.dot(r.candidate.P.ldlt().solve(d));
    c.nees.push_back(nees);
    const bool beyond = !(nees <= options.wrong_merge_chi2);
    c.over_bound += beyond;
    if (r.verdict == "adopted") {
      ++c.adopted;
      c.wrong_adopted += beyond;
      first_adoption.emplace(r.peer, r.t);
    }
  }
  for (const auto& [peer, t] : first_adoption) c.first_adoption_s.push_back(t);
  return c;
}

/// Positions of `estimate` paired by time with those of `truth` mapped by `to_frame`.
void pairPositions(const std::vector<TumPose>& estimate, const std::vector<StateRecord>& truth,
                   const FrameRelation& to_frame, double tolerance,
                   std::vector<Eigen::Vector3d>* est, std::vector<Eigen::Vector3d>* tru) {
  std::vector<double> te, tt;
  for (const TumPose& p : estimate) te.push_back(p.t);
  for (const StateRecord& s : truth) tt.push_back(s.t);
  for (const auto& [i, j] : associateByTime(te, tt, tolerance)) {
    est->push_back(estimate[i].p_BinN);
    tru->push_back(to_frame.apply(truth[j].x.head<3>()));
  }
}

double rmse(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
            const Eigen::Isometry3d& align) {
  double sum = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) sum += (align * a[k] - b[k]).squaredNorm();
  return std::sqrt(sum / static_cast<double>(std::max<std::size_t>(a.size(), 1)));
}

/// Team-frame estimate and world truth of one agent, for the group's alignment.
struct TeamPairs {
  std::size_t agent = 0;  ///< index into TeamEvaluation::agents
  std::vector<Eigen::Vector3d> est, world;
};

/// One SE(3) alignment (Umeyama, no scale) of the largest group's estimates to their truths.
void alignLargestGroup(const std::map<int, std::vector<TeamPairs>>& groups, TeamEvaluation* team) {
  const std::vector<TeamPairs>* largest = nullptr;
  for (const auto& [root, members] : groups)
    if (!largest || members.size() > largest->size()) largest = &members, team->root = root;
  if (!largest) {
    team->notes.push_back("no agent merged: no team-frame trajectory_team.tum");
    return;
  }
  std::vector<Eigen::Vector3d> est, world;
  for (const TeamPairs& m : *largest) {
    est.insert(est.end(), m.est.begin(), m.est.end());
    world.insert(world.end(), m.world.begin(), m.world.end());
  }
  if (est.size() < 3) {
    team->notes.push_back("team alignment: fewer than 3 estimate/truth pairs");
    return;
  }
  Eigen::Matrix3Xd E(3, est.size()), W(3, world.size());
  for (std::size_t k = 0; k < est.size(); ++k) E.col(k) = est[k], W.col(k) = world[k];
  const Eigen::Isometry3d T = alignRigid(E, W);
  team->team_ate_aligned_m = rmse(est, world, T);
  for (const TeamPairs& m : *largest)
    if (!m.est.empty()) team->agents[m.agent].team_ate_aligned_m = rmse(m.est, m.world, T);
}

}  // namespace

Expected<TeamEvaluation> evaluateTeam(const std::string& run_dir, const std::string& gt_dir,
                                      const TeamEvaluationOptions& options) {
  auto info = readRunInfo(run_dir);
  if (!info.ok()) return info.status();
  auto ids = listAgentIds(run_dir);
  if (!ids.ok()) return ids.status();
  // Simulation: truth.csv in each own frame, frames_in_world the link to the world. A
  // recording's ground truth (--gt) is already in one world frame whose relation to any
  // agent's frame is unknown: only the aligned team figure exists then.
  const bool frames_known = gt_dir.empty();
  TeamEvaluation team;
  std::map<int, std::vector<TeamPairs>> groups;
  for (int id : *ids) {
    auto run = readAgentRun(run_dir, id);
    if (!run.ok()) return run.status();
    std::vector<StateRecord> truth = run->truth;
    if (!frames_known) {
      bool has_velocity = true;
      auto gt = readGroundTruth(gt_dir, id, &has_velocity);
      if (!gt.ok()) return gt.status();
      truth = std::move(*gt);
    }
    TeamAgentEvaluation ev;
    ev.id = id;
    if (!run->trajectory.empty())
      ev.flight_s = run->trajectory.back().t - run->trajectory.front().t;
    std::vector<TumPose> own_truth;
    for (const StateRecord& s : truth) own_truth.push_back(tumPoseFromState(s.t, s.x));
    const AteOptions own{options.time_tolerance_s,
                         frames_known ? Alignment::kNone : Alignment::kSE3};
    if (auto ate = absoluteTrajectoryError(run->trajectory, own_truth, own); ate.ok())
      ev.own_ate_m = ate->rmse_m;
    const FrameRelation own_in_world = inWorld(frames_known ? frameOf(*info, id) : Vector4d());
    if (run->team && !run->team->poses.empty()) {
      const std::vector<TumPose>& poses = run->team->poses;
      ev.root = run->team->root;
      ev.merged_at_s = poses.front().t;
      if (ev.flight_s > 0.0) ev.coverage = (poses.back().t - poses.front().t) / ev.flight_s;
      TeamPairs pairs;
      pairs.agent = team.agents.size();
      pairPositions(poses, truth, own_in_world, options.time_tolerance_s, &pairs.est, &pairs.world);
      if (frames_known) {
        // The truth in the root's frame: own → world → root.
        const FrameRelation own_in_root =
            inWorld(frameOf(*info, *ev.root)).inverse().compose(own_in_world);
        std::vector<TumPose> truth_in_root = own_truth;
        for (TumPose& p : truth_in_root) p.p_BinN = own_in_root.apply(p.p_BinN);
        const AteOptions unaligned{options.time_tolerance_s, Alignment::kNone};
        if (auto ate = absoluteTrajectoryError(poses, truth_in_root, unaligned); ate.ok())
          ev.team_ate_m = ate->rmse_m;
      }
      groups[*ev.root].push_back(std::move(pairs));
    }
    const std::string relations = agentDir(run_dir, id) + "/relations.csv";
    if (frames_known && std::ifstream(relations).good()) {
      auto rows = readRelations(relations);
      if (!rows.ok()) return rows.status();
      ev.relations = checkRelations(*rows, *info, id, options);
    }
    team.agents.push_back(std::move(ev));
  }
  alignLargestGroup(groups, &team);
  if (!frames_known)
    team.notes.push_back(
        "ground truth from --gt: the frames' truth is unknown, so the team ATE is aligned only "
        "and relations are not checked");
  return team;
}

namespace {

Json optionalJson(const std::optional<double>& x) {
  return x ? Json(*x) : Json();
}

Json relationJson(const RelationCheck& c) {
  Json j = Json::object();
  j["verified"] = c.verified;
  j["failed"] = c.failed;
  j["adopted"] = c.adopted;
  j["wrong_adopted"] = c.wrong_adopted;
  j["over_bound"] = c.over_bound;
  j["nees_mean"] = c.nees.empty() ? Json()
                                  : Json(std::accumulate(c.nees.begin(), c.nees.end(), 0.0) /
                                         static_cast<double>(c.nees.size()));
  j["nees_max"] = c.nees.empty() ? Json() : Json(*std::max_element(c.nees.begin(), c.nees.end()));
  j["nees"] = c.nees;
  j["first_adoption_s"] = c.first_adoption_s;
  return j;
}

}  // namespace

Json teamSummaryJson(const TeamEvaluation& team) {
  Json root = Json::object();
  root["root"] = team.root ? Json(*team.root) : Json();
  root["team_ate_aligned_m"] = optionalJson(team.team_ate_aligned_m);
  root["alignment"] = "se3";
  Json agents = Json::object();
  for (const TeamAgentEvaluation& ev : team.agents) {
    Json a = Json::object();
    a["flight_s"] = ev.flight_s;
    a["own_ate_m"] = optionalJson(ev.own_ate_m);
    a["root"] = ev.root ? Json(*ev.root) : Json();
    a["merged_at_s"] = optionalJson(ev.merged_at_s);
    a["coverage"] = optionalJson(ev.coverage);
    a["team_ate_m"] = optionalJson(ev.team_ate_m);
    a["team_ate_aligned_m"] = optionalJson(ev.team_ate_aligned_m);
    a["relations"] = ev.relations ? relationJson(*ev.relations) : Json();
    agents[std::to_string(ev.id)] = std::move(a);
  }
  root["agents"] = std::move(agents);
  root["notes"] = team.notes;
  return root;
}

std::string teamSummaryTable(const TeamEvaluation& team) {
  const auto cell = eval_detail::tableCell;
  std::string out;
  char line[512];
  std::snprintf(line, sizeof(line), "%-6s %9s %10s %5s %10s %8s %11s %13s %9s %11s %6s\n", "agent",
                "flight[s]", "own ATE[m]", "root", "merged[s]", "cover[%]", "team ATE[m]",
                "aligned ATE[m]", "verified", "rel NEES", "wrong");
  out += line;
  for (const TeamAgentEvaluation& ev : team.agents) {
    std::optional<double> cover, nees, verified, wrong, root;
    if (ev.coverage) cover = 100.0 * *ev.coverage;
    if (ev.root) root = *ev.root;
    if (ev.relations) {
      verified = ev.relations->verified;
      wrong = ev.relations->wrong_adopted;
      const auto& n = ev.relations->nees;
      if (!n.empty())
        nees = std::accumulate(n.begin(), n.end(), 0.0) / static_cast<double>(n.size());
    }
    std::snprintf(line, sizeof(line), "%-6d %9.1f %10s %5s %10s %8s %11s %13s %9s %11s %6s\n",
                  ev.id, ev.flight_s, cell(ev.own_ate_m, "%.4f").c_str(),
                  cell(root, "%.0f").c_str(), cell(ev.merged_at_s, "%.1f").c_str(),
                  cell(cover, "%.1f").c_str(), cell(ev.team_ate_m, "%.4f").c_str(),
                  cell(ev.team_ate_aligned_m, "%.4f").c_str(), cell(verified, "%.0f").c_str(),
                  cell(nees, "%.2f").c_str(), cell(wrong, "%.0f").c_str());
    out += line;
  }
  std::snprintf(line, sizeof(line),
                "team (frame of agent %s): ATE %s m after one SE(3) alignment\n",
                team.root ? std::to_string(*team.root).c_str() : "-",
                cell(team.team_ate_aligned_m, "%.4f").c_str());
  out += line;
  return out;
}

}  // namespace cvslam
