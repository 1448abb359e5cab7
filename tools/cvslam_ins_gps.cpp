// cvslam_ins_gps — GPS-aided INS, thesis chapter 3 (docs/ins_gps.md): simulates a flight from
// a config, runs the KF, EKF, UKF, SDRE and NH∞ filters on the same IMU/GPS data, prints the
// analogue of Tables 3.2–3.3 (markdown), writes one CSV per filter and optionally the plots.
// A thin shell: simulation in common/sim (gps_flight.h), filters and metrics in common/insgps.

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "cvslam/insgps/insgps_run.h"
#include "cvslam/io/cli.h"
#include "cvslam/io/config_node.h"
#include "cvslam/sim/gps_flight.h"

namespace {

constexpr const char* kUsage =
    R"(usage: cvslam_ins_gps --config FILE [--out DIR] [options]

Simulates a flight with an IMU and a GPS receiver (config/ins_gps/*.yaml), runs the
INS/GPS filters of thesis chapter 3 on the same data (kf: KF on the linear error model,
ekf, ukf, sdre, nhinf) and prints per-axis error standard deviations and the computation
time per step as markdown tables (the thesis's Tables 3.2 and 3.3).

  --config FILE      flight and filter configuration (required)
  --out DIR          write <filter>.csv (t, estimate, truth, 1σ), gps.csv and tables.md
  --seed N           override the config's seed (IMU, GPS and initial-error streams)
  --seeds N          run N seeds (seed, seed+1, ...) and print the tables of the mean
                     statistics (CSV and plots: the first seed) (default 1)
  --from S           statistics from this time on [s] (default 0: the whole flight)
  --csv-every N      write every N-th IMU sample to the CSV files (default 1)
  --plot             with --out: also draw the figures (scripts/plot_ins_gps.py, python3)
  -h, --help         this text
)";

int fail(const std::string& message) {
  std::cerr << "cvslam_ins_gps: " << message << '\n';
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string config_path, out_dir;
  int64_t seed = -1;
  double from_s = 0.0;
  int csv_every = 1;
  int seeds = 1;
  bool plot = false;
  CLI::App app("GPS-aided INS filters of thesis chapter 3", "cvslam_ins_gps");
  app.add_option("--config", config_path)->required();
  app.add_option("--out", out_dir);
  app.add_option("--seed", seed)->check(cvslam::cli::kNonNegative);
  app.add_option("--from", from_s)->check(cvslam::cli::kNonNegative);
  app.add_option("--csv-every", csv_every)->check(cvslam::cli::kPositive);
  app.add_option("--seeds", seeds)->check(CLI::Range(1, 1000));
  app.add_flag("--plot", plot);
  if (auto exit_code = cvslam::cli::parse(app, argc, argv, kUsage)) return *exit_code;
  if (plot && out_dir.empty()) return fail("--plot needs --out");

  auto cfg = cvslam::ConfigNode::loadFile(config_path);
  if (!cfg.ok()) return fail(cfg.status().message());
  const std::string base_dir = std::filesystem::path(config_path).parent_path().string();
  cvslam::sim::GpsFlightOptions flight_options;
  cvslam::insgps::InsGpsOptions filter_options;
  cvslam::Status st = flight_options.load(*cfg, base_dir);
  if (st.ok()) st = filter_options.load(cfg->child("filters"));
  if (st.ok()) st = cfg->finish();
  if (!st.ok()) return fail(st.message());
  if (seed >= 0) flight_options.seed = static_cast<uint64_t>(seed);

  if (!out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    if (ec) return fail("cannot create " + out_dir + ": " + ec.message());
  }
  const uint64_t first_seed = flight_options.seed;
  std::vector<cvslam::insgps::FilterTrack> tracks;  // of the first seed
  std::vector<std::vector<cvslam::insgps::ErrorStats>> runs(filter_options.filters.size());
  std::size_t imu_samples = 0, gps_fixes = 0;
  for (int s = 0; s < seeds; ++s) {
    flight_options.seed = first_seed + static_cast<uint64_t>(s);
    auto flight = cvslam::sim::simulateGpsFlight(flight_options);
    if (!flight.ok()) return fail(flight.status().message());
    const cvslam::insgps::FlightData data{flight->imu, flight->gps, flight->truth};
    imu_samples = data.imu.size();
    gps_fixes = data.gps.size();
    cvslam::insgps::StateVector x0;
    cvslam::insgps::StateMatrix P0;
    cvslam::insgps::initialEstimate(data.truth.front(), filter_options, flight_options.seed, &x0,
                                    &P0);
    const bool write = !out_dir.empty() && s == 0;
    if (write) {
      st = cvslam::insgps::writeGpsCsv(out_dir + "/gps.csv", data.gps);
      if (!st.ok()) return fail(st.message());
    }
    for (std::size_t i = 0; i < filter_options.filters.size(); ++i) {
      const std::string& name = filter_options.filters[i];
      auto filter = cvslam::insgps::makeFilter(name, filter_options);
      if (!filter.ok()) return fail(filter.status().message());
      auto track = cvslam::insgps::runFilter(*filter.value(), data, x0, P0);
      if (!track.ok()) return fail(track.status().message());
      runs[i].push_back(cvslam::insgps::errorStats(*track, data, from_s));
      if (write) {
        st = cvslam::insgps::writeTrackCsv(out_dir + "/" + name + ".csv", *track, data, csv_every);
        if (!st.ok()) return fail(st.message());
      }
      if (s == 0) tracks.push_back(std::move(track.value()));
    }
  }
  std::vector<cvslam::insgps::ErrorStats> stats;
  for (const auto& r : runs) stats.push_back(cvslam::insgps::meanStats(r));
  const std::string tables = cvslam::insgps::markdownTables(tracks, stats);
  std::cout << "flight " << config_path << "  seed " << first_seed;
  if (seeds > 1) std::cout << ".." << first_seed + static_cast<uint64_t>(seeds - 1) << " (mean)";
  std::cout << "  " << imu_samples << " IMU samples, " << gps_fixes << " GPS fixes\n\n" << tables;
  if (!out_dir.empty()) {
    std::ofstream(out_dir + "/tables.md") << tables;
    if (plot) {
      std::cout.flush();
      const std::string cmd =
          "/usr/bin/python3 " CVSLAM_SCRIPTS_DIR "/plot_ins_gps.py '" + out_dir + "'";
      if (std::system(cmd.c_str()) != 0) return fail("plotting failed: " + cmd);
    }
  }
  return 0;
}
