// cvslam_eval — evaluates a run folder (docs/run_format.md): per-agent table on stdout and the
// summary JSON. A thin shell: parsing and metrics live in common/ (eval/, io/).

#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>

#include "cvslam/eval/run_evaluation.h"
#include "cvslam/io/run_reader.h"

namespace {

constexpr const char* kUsage =
    R"(usage: cvslam_eval --run DIR [--gt DIR] [--summary-json F] [options]

Evaluates an estimator run (docs/run_format.md): per agent ATE RMSE, INS ATE, RPE per 10 m,
NEES, the thesis's Rco per state (§5.7.3), landmark error mean/std per axis, max state size,
median frame time and bytes sent per second. Prints a table; writes the summary JSON.

  --run DIR              run folder with agent_<id>/ sub-folders (required)
  --gt DIR               ground truth folder (agent_<id>/truth.csv, agent_<id>/trajectory.tum
                         or <agent>/mav0/state_groundtruth_estimate0/data.csv, and
                         landmarks.csv); default: truth.csv inside the run folder
  --summary-json F       write the summary JSON to F
  --align none|se3       align the estimate to the truth (default none: shared NED frame)
  --time-tolerance S     max time difference for estimate/truth pairs [s] (default 0.01)
  --rpe-segment M        RPE segment length [m] (default 10)
  --co-window N          steps in the true-uncertainty RMS of co/Rco (default 1)
  --quiet                no table
  -h, --help             this text
)";

int fail(const std::string& message) {
  std::cerr << "cvslam_eval: " << message << '\n';
  return 1;
}

bool parseDouble(const std::string& s, double& out) {
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return !s.empty() && *end == '\0';
}

}  // namespace

int main(int argc, char** argv) {
  std::string run_dir, gt_dir, summary_path;
  cvslam::RunEvaluationOptions options;
  bool quiet = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&](std::string& out) {
      if (i + 1 >= argc) return false;
      out = argv[++i];
      return true;
    };
    std::string v;
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    } else if (arg == "--quiet") {
      quiet = true;
    } else if (arg == "--run") {
      if (!value(run_dir)) return fail("--run needs a folder");
    } else if (arg == "--gt") {
      if (!value(gt_dir)) return fail("--gt needs a folder");
    } else if (arg == "--summary-json") {
      if (!value(summary_path)) return fail("--summary-json needs a file name");
    } else if (arg == "--align") {
      if (!value(v) || (v != "none" && v != "se3")) return fail("--align must be none or se3");
      options.alignment = v == "se3" ? cvslam::Alignment::kSE3 : cvslam::Alignment::kNone;
    } else if (arg == "--time-tolerance") {
      if (!value(v) || !parseDouble(v, options.time_tolerance_s) || options.time_tolerance_s < 0)
        return fail("--time-tolerance needs a number >= 0");
    } else if (arg == "--rpe-segment") {
      if (!value(v) || !parseDouble(v, options.rpe_segment_m) || options.rpe_segment_m <= 0)
        return fail("--rpe-segment needs a number > 0");
    } else if (arg == "--co-window") {
      double w = 0;
      if (!value(v) || !parseDouble(v, w) || w < 1)
        return fail("--co-window needs an integer >= 1");
      options.co_window = static_cast<int>(w);
    } else {
      return fail("unknown argument '" + arg + "' (try --help)");
    }
  }
  if (run_dir.empty()) return fail("--run DIR is required (try --help)");

  auto info = cvslam::readRunInfo(run_dir);
  if (!info.ok()) return fail(info.status().message());
  auto agents = cvslam::evaluateRun(run_dir, gt_dir, options);
  if (!agents.ok()) return fail(agents.status().message());

  if (!quiet) {
    std::cout << "run " << run_dir << "  mode " << (info->mode.empty() ? "?" : info->mode)
              << "  filter " << (info->filter.empty() ? "?" : info->filter) << '\n'
              << cvslam::summaryTable(*agents);
    for (const auto& ev : *agents)
      for (const auto& n : ev.notes) std::cout << "  agent " << ev.id << ": " << n << '\n';
  }
  if (!summary_path.empty()) {
    std::ofstream out(summary_path);
    if (!out) return fail(summary_path + ": cannot write");
    out << cvslam::summaryJson(*info, *agents, options).dump(2);
    if (!out) return fail(summary_path + ": write failed");
  }
  return 0;
}
