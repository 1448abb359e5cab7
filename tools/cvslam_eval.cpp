// cvslam_eval — evaluates a run folder (docs/run_format.md): per-agent table on stdout and the
// summary JSON. A thin shell: parsing and metrics live in common/ (eval/, io/).

#include <cmath>
#include <iostream>
#include <limits>
#include <string>

#include "cvslam/eval/run_evaluation.h"
#include "cvslam/eval/team_evaluation.h"
#include "cvslam/io/cli.h"
#include "cvslam/io/json_file.h"
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
  --align none|se3|yaw   align the estimate to the truth before the ATE (default none:
                         shared NED frame); se3: rigid Umeyama; yaw: rotation about the
                         vertical + translation (4-DoF, for gravity-aligned estimates;
                         a z-up truth against a NED estimate is handled and noted)
  --time-tolerance S     max time difference for estimate/truth pairs [s] (default 0.01)
  --rpe-segment M        RPE segment length [m] (default 10)
  --co-window N          steps in the true-uncertainty RMS of co/Rco (default 1)
  --team                 also evaluate the team (docs/merge.md "Evaluating a team"): per
                         agent its own-frame ATE, its merge, its trajectory_team.tum
                         against the truth in its root's frame, the team's ATE after ONE
                         SE(3) alignment of every merged agent, and in simulation each
                         verified frame relation against the truth (NEES, wrong merges)
  --team-json F          write that evaluation to F (implies --team)
  --quiet                no table
  -h, --help             this text
)";

int fail(const std::string& message) {
  std::cerr << "cvslam_eval: " << message << '\n';
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string run_dir, gt_dir, summary_path, team_path, align = "none";
  cvslam::RunEvaluationOptions options;
  bool quiet = false, team = false;
  CLI::App app("evaluates a run folder", "cvslam_eval");
  app.add_option("--run", run_dir)->required();
  app.add_option("--gt", gt_dir);
  app.add_option("--summary-json", summary_path);
  app.add_option("--align", align)->check(CLI::IsMember({"none", "se3", "yaw"}));
  app.add_option("--time-tolerance", options.time_tolerance_s)->check(cvslam::cli::kNonNegative);
  app.add_option("--rpe-segment", options.rpe_segment_m)->check(cvslam::cli::kPositive);
  app.add_option("--co-window", options.co_window)
      ->check(cvslam::cli::numberValidator("WINDOW", "a whole number ≥ 1", [](double x) {
        return x >= 1.0 && x == std::floor(x) && x <= std::numeric_limits<int>::max();
      }));
  app.add_flag("--team", team);
  app.add_option("--team-json", team_path);
  app.add_flag("--quiet", quiet);
  if (auto exit_code = cvslam::cli::parse(app, argc, argv, kUsage)) return *exit_code;
  options.alignment = align == "se3"   ? cvslam::Alignment::kSE3
                      : align == "yaw" ? cvslam::Alignment::kYaw
                                       : cvslam::Alignment::kNone;

  auto info = cvslam::readRunInfo(run_dir);
  if (!info.ok()) return fail(info.status().message());
  auto agents = cvslam::evaluateRun(run_dir, gt_dir, options);
  if (!agents.ok()) return fail(agents.status().message());

  if (!quiet) {
    std::cout << "run " << run_dir << "  mode " << (info->mode.empty() ? "?" : info->mode)
              << "  filter " << (info->filter.empty() ? "?" : info->filter)
              << (info->linearised_at_truth ? "  Jacobians at the truth (ideal EKF diagnostic)"
                                            : "")
              << '\n'
              << cvslam::summaryTable(*agents);
    for (const auto& ev : *agents)
      for (const auto& n : ev.notes) std::cout << "  agent " << ev.id << ": " << n << '\n';
  }
  if (!summary_path.empty()) {
    const cvslam::Status written =
        cvslam::writeJsonFile(summary_path, cvslam::summaryJson(*info, *agents, options));
    if (!written.ok()) return fail(written.message());
  }
  if (team || !team_path.empty()) {
    cvslam::TeamEvaluationOptions team_options;
    team_options.time_tolerance_s = options.time_tolerance_s;
    auto evaluation = cvslam::evaluateTeam(run_dir, gt_dir, team_options);
    if (!evaluation.ok()) return fail(evaluation.status().message());
    if (!quiet) {
      std::cout << cvslam::teamSummaryTable(*evaluation);
      for (const auto& n : evaluation->notes) std::cout << "  team: " << n << '\n';
    }
    if (!team_path.empty()) {
      const cvslam::Status written =
          cvslam::writeJsonFile(team_path, cvslam::teamSummaryJson(*evaluation));
      if (!written.ok()) return fail(written.message());
    }
  }
  return 0;
}
