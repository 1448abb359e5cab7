#include "cvslam/io/run_writer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numeric>

#include "cvslam/io/build_info.h"
#include "cvslam/io/json_file.h"
#include "cvslam/io/time_format.h"

namespace cvslam {
namespace {

/// %.10g keeps sub-millimetre and micro-radian resolution at any scale.
void appendNumber(std::string& line, double x) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.10g", x);
  line += buf;
}

/// Column names of an estimate: the names, then var_<name> and, if `full`, cov_i_j (i < j).
template <std::size_t N>
std::string estimateHeader(const char* const (&names)[N], bool with_covariance, bool full) {
  std::string h = "t";
  for (const char* n : names) h += std::string(",") + n;
  if (!with_covariance) return h;
  for (const char* n : names) h += std::string(",var_") + n;
  if (full)
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = i + 1; j < N; ++j)
        h += ",cov_" + std::to_string(i) + "_" + std::to_string(j);
  return h;
}

/// t and the values of x: the row of estimateHeader without covariance (truth.csv).
template <int N>
std::string valuesRow(double t, const Eigen::Matrix<double, N, 1>& x) {
  std::string line;
  appendSeconds(line, t);
  for (int i = 0; i < N; ++i) line += ',', appendNumber(line, x(i));
  return line;
}

/// The row of estimateHeader: t, x, diag(P) and, if `full`, P's upper triangle.
template <int N>
std::string estimateRow(double t, const Eigen::Matrix<double, N, 1>& x,
                        const Eigen::Matrix<double, N, N>& P, bool full) {
  std::string line = valuesRow<N>(t, x);
  for (int i = 0; i < N; ++i) line += ',', appendNumber(line, P(i, i));
  if (full)
    for (int i = 0; i < N; ++i)
      for (int j = i + 1; j < N; ++j) line += ',', appendNumber(line, P(i, j));
  return line;
}

constexpr const char* kBiasNames[6] = {"ba_x", "ba_y", "ba_z", "bg_x", "bg_y", "bg_z"};

}  // namespace

std::string agentDir(const std::string& run_dir, int agent_id) {
  return run_dir + "/agent_" + std::to_string(agent_id);
}

std::string teamFrameComment(int root) {
  return kTeamFramePrefix + std::to_string(root);
}

AgentRunWriter::~AgentRunWriter() {
  if (open_) close();
}

Status AgentRunWriter::open(const std::string& run_dir, int agent_id,
                            const AgentRunWriterOptions& options) {
  options_ = options;
  agent_id_ = agent_id;
  dir_ = agentDir(run_dir, agent_id);
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) return Status::Error(dir_ + ": cannot create folder: " + ec.message());
  if (Status s = trajectory_.open(dir_ + "/trajectory.tum"); !s.ok()) return s;
  states_.open(dir_ + "/states.csv", std::ios::trunc);
  truth_.open(dir_ + "/truth.csv", std::ios::trunc);
  if (!states_ || !truth_) return Status::Error(dir_ + ": cannot write states.csv / truth.csv");
  states_ << estimateHeader(kVehicleStateNames, true, options_.full_covariance) << '\n';
  truth_ << estimateHeader(kVehicleStateNames, false, false) << '\n';
  stats_ = RunStats{};
  have_time_ = false;
  open_ = true;
  return Status::Ok();
}

Status AgentRunWriter::addState(double t, const Vector9d& x, const Matrix9d& P) {
  if (!open_) return Status::Error("AgentRunWriter: not open");
  if (Status s = trajectory_.add(tumPoseFromState(t, x)); !s.ok()) return s;
  states_ << estimateRow<9>(t, x, P, options_.full_covariance) << '\n';
  if (!have_time_) t_first_ = t;
  t_last_ = t;
  have_time_ = true;
  return states_ ? Status::Ok() : Status::Error(dir_ + "/states.csv: write failed");
}

Status AgentRunWriter::addBiases(double t, const Vector6d& b, const Matrix6d& P,
                                 const Vector6d& b_true) {
  if (!open_) return Status::Error("AgentRunWriter: not open");
  if (!biases_.is_open()) {
    biases_.open(dir_ + "/biases.csv", std::ios::trunc);
    if (!biases_) return Status::Error("cannot write " + dir_ + "/biases.csv");
    biases_ << estimateHeader(kBiasNames, true, true);
    for (const char* n : kBiasNames) biases_ << ",true_" << n;
    biases_ << '\n';
  }
  std::string line = estimateRow<6>(t, b, P, true);
  for (int i = 0; i < 6; ++i) line += ',', appendNumber(line, b_true(i));
  biases_ << line << '\n';
  return biases_ ? Status::Ok() : Status::Error(dir_ + "/biases.csv: write failed");
}

Status AgentRunWriter::addTruth(double t, const Vector9d& x_true) {
  if (!open_) return Status::Error("AgentRunWriter: not open");
  truth_ << valuesRow<9>(t, x_true) << '\n';
  return truth_ ? Status::Ok() : Status::Error(dir_ + "/truth.csv: write failed");
}

Status AgentRunWriter::addInsState(double t, const Vector9d& x_ins) {
  if (!open_) return Status::Error("AgentRunWriter: not open");
  if (!ins_.isOpen())
    if (Status s = ins_.open(dir_ + "/ins_trajectory.tum"); !s.ok()) return s;
  return ins_.add(tumPoseFromState(t, x_ins));
}

Status AgentRunWriter::addTeamState(double t, int root, const Vector9d& x_team) {
  if (!open_) return Status::Error("AgentRunWriter: not open");
  if (!team_.isOpen() || root != team_root_) {
    team_.close();
    if (Status s = team_.open(dir_ + "/trajectory_team.tum", teamFrameComment(root)); !s.ok())
      return s;
    team_root_ = root;
  }
  return team_.add(tumPoseFromState(t, x_team));
}

Status AgentRunWriter::writeLandmarks(const std::vector<LandmarkRecord>& landmarks) const {
  if (dir_.empty()) return Status::Error("AgentRunWriter: not open");
  return writeLandmarksFile(dir_ + "/landmarks.csv", landmarks);
}

Status writeLandmarksFile(const std::string& path, const std::vector<LandmarkRecord>& landmarks) {
  std::ofstream out(path, std::ios::trunc);
  if (!out) return Status::Error(path + ": cannot write");
  bool any_truth = false;
  for (const auto& l : landmarks) any_truth = any_truth || l.truth.has_value();
  out << "id,x,y,z,var_x,var_y,var_z" << (any_truth ? ",true_x,true_y,true_z" : "") << '\n';
  for (const auto& l : landmarks) {
    std::string line = std::to_string(l.id);
    for (int i = 0; i < 3; ++i) line += ',', appendNumber(line, l.p_LinN(i));
    for (int i = 0; i < 3; ++i) line += ',', appendNumber(line, l.var(i));
    if (any_truth) {
      for (int i = 0; i < 3; ++i) {
        line += ',';
        if (l.truth)
          appendNumber(line, (*l.truth)(i));
        else
          line += "nan";
      }
    }
    out << line << '\n';
  }
  return out ? Status::Ok() : Status::Error(path + ": write failed");
}

TimeSummary summariseTimes(std::vector<double> samples) {
  TimeSummary s;
  if (samples.empty()) return s;
  std::sort(samples.begin(), samples.end());
  const auto at = [&](double q) {
    return samples[static_cast<std::size_t>(q * static_cast<double>(samples.size() - 1) + 0.5)];
  };
  s.median_ms = at(0.5);
  s.p95_ms = at(0.95);
  s.max_ms = samples.back();
  s.mean_ms =
      std::accumulate(samples.begin(), samples.end(), 0.0) / static_cast<double>(samples.size());
  return s;
}

std::string stageTimesLine(const RunStats& stats) {
  const auto median = [&stats](const char* stage) {
    const auto it = stats.stage_ms.find(stage);
    return it == stats.stage_ms.end() ? std::numeric_limits<double>::quiet_NaN()
                                      : summariseTimes(it->second).median_ms;
  };
  if (stats.stage_ms.find("frame") == stats.stage_ms.end()) return "";
  char buf[320];
  if (stats.stage_ms.find("front_end") == stats.stage_ms.end()) {
    std::snprintf(buf, sizeof(buf), "frame median %.2f ms", median("frame"));
    return buf;
  }
  std::snprintf(buf, sizeof(buf),
                "frame median %.2f ms: front end %.2f (detect %.2f, stereo %.2f, describe %.2f, "
                "index %.2f), association %.2f, filter %.2f",
                median("frame"), median("front_end"), median("front_end.detect"),
                median("front_end.stereo"), median("front_end.describe"), median("front_end.index"),
                median("association"), median("filter"));
  return buf;
}

Status writeRunStats(const std::string& path, int agent_id, const RunStats& stats) {
  Json frames = Json::object();
  std::vector<double> t, ms, sigma;
  std::vector<int> size, lms;
  for (const FrameStats& f : stats.frames) {
    t.push_back(f.t);
    ms.push_back(f.time_ms);
    size.push_back(f.state_size);
    lms.push_back(f.landmarks);
    sigma.push_back(f.landmark_sigma_mean_m);  // NaN → null
  }
  frames["t_s"] = t;
  frames["time_ms"] = ms;
  frames["state_size"] = size;
  frames["landmarks"] = lms;
  frames["landmark_sigma_mean_m"] = sigma;
  std::vector<double> latency;
  bool any_latency = false;
  for (const FrameStats& f : stats.frames) {
    latency.push_back(f.latency_ms);
    any_latency = any_latency || std::isfinite(f.latency_ms);
  }
  if (any_latency) frames["latency_ms"] = latency;
  Json root = Json::object();
  root["agent_id"] = agent_id;
  root["duration_s"] = stats.duration_s;
  root["bytes_sent"] = stats.bytes_sent;
  root["bytes_received"] = stats.bytes_received;
  if (!stats.bytes_sent_per_stream.empty()) {
    Json bytes = Json::object(), rates = Json::object();
    for (const auto& [stream, n] : stats.bytes_sent_per_stream) {
      bytes[stream] = n;
      rates[stream] = stats.duration_s > 0.0 ? static_cast<double>(n) / stats.duration_s
                                             : std::numeric_limits<double>::quiet_NaN();
    }
    root["bytes_sent_per_stream"] = std::move(bytes);
    root["bytes_sent_per_s"] = std::move(rates);
  }
  root["frames"] = std::move(frames);
  if (!stats.stage_ms.empty()) {
    Json stages = Json::object();
    for (const auto& [stage, samples] : stats.stage_ms) {
      if (samples.empty()) continue;
      const TimeSummary st = summariseTimes(samples);
      Json s = Json::object();
      s["frames"] = static_cast<int64_t>(samples.size());
      s["mean"] = st.mean_ms;
      s["median"] = st.median_ms;
      s["p95"] = st.p95_ms;
      stages[stage] = std::move(s);
    }
    root["stage_ms"] = std::move(stages);
  }
  return writeJsonFile(path, root);
}

double AgentRunWriter::durationSoFar() const {
  double first = have_time_ ? t_first_ : 0.0, last = have_time_ ? t_last_ : 0.0;
  if (!stats_.frames.empty()) {
    first = have_time_ ? std::min(first, stats_.frames.front().t) : stats_.frames.front().t;
    last = std::max(last, stats_.frames.back().t);
  }
  return last - first;
}

Status AgentRunWriter::flush() {
  if (!open_) return Status::Error("AgentRunWriter: not open");
  trajectory_.flush();
  ins_.flush();
  team_.flush();
  states_.flush();
  truth_.flush();
  if (biases_.is_open()) biases_.flush();
  if (!std::filesystem::exists(dir_ + "/landmarks.csv"))
    if (Status s = writeLandmarks({}); !s.ok()) return s;
  RunStats snapshot = stats_;
  if (snapshot.duration_s <= 0.0) snapshot.duration_s = durationSoFar();
  return writeRunStats(dir_ + "/stats.json", agent_id_, snapshot);
}

Status AgentRunWriter::close() {
  if (!open_) return Status::Ok();
  open_ = false;
  trajectory_.close();
  ins_.close();
  team_.close();
  states_.close();
  truth_.close();
  if (biases_.is_open()) biases_.close();
  if (stats_.duration_s <= 0.0) stats_.duration_s = durationSoFar();
  // A run that never wrote its map still leaves a valid (empty) landmarks.csv.
  if (!std::filesystem::exists(dir_ + "/landmarks.csv"))
    if (Status s = writeLandmarks({}); !s.ok()) return s;
  return writeRunStats(dir_ + "/stats.json", agent_id_, stats_);
}

Status writeRunInfo(const std::string& run_dir, const RunInfo& info) {
  std::error_code ec;
  std::filesystem::create_directories(run_dir, ec);
  if (ec) return Status::Error(run_dir + ": cannot create folder: " + ec.message());
  Json root = Json::object();
  root["mode"] = info.mode;
  root["filter"] = info.filter;
  root["map"] = info.map;
  root["scenario"] = info.scenario;
  if (info.seed) root["seed"] = *info.seed;
  if (info.duration_s) root["duration_s"] = *info.duration_s;
  const auto text = [&](const char* key, const std::string& value) {
    if (!value.empty()) root[key] = value;
  };
  text("sensing", info.sensing);
  text("world", info.world);
  text("pixel_noise", info.pixel_noise);
  if (!info.agents.empty()) root["agents"] = info.agents;
  for (const auto& [id, f] : info.frames_in_world)
    root["frames_in_world"][std::to_string(id)] = {f(0), f(1), f(2), f(3)};
  if (info.linearised_at_truth) root["linearised_at_truth"] = true;
  text("config", info.config);
  text("program", info.program);
  root["commit"] = info.commit.empty() ? std::string(buildCommit()) : info.commit;
  return writeJsonFile(run_dir + "/run.json", root);
}

}  // namespace cvslam
