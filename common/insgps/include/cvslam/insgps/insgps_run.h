#pragma once
// Runs the INS/GPS filters on one flight and measures them (thesis §3.7.2, Tables 3.2–3.3):
// the same IMU and GPS data for every filter, the same initial estimate, the error statistics
// per axis and the computation time per step. The programs (cvslam_ins_gps) and the tests are
// thin shells over this.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/ins/ins_propagator.h"
#include "cvslam/insgps/gps_aided_ekf.h"
#include "cvslam/insgps/gps_aided_filter.h"
#include "cvslam/insgps/gps_aided_kf.h"
#include "cvslam/insgps/gps_aided_ukf.h"
#include "cvslam/insgps/nhinf_gps_filter.h"
#include "cvslam/insgps/sdre_filter.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::insgps {

/// The filters' options (config section `filters`: ins, kf, ekf, ukf, sdre, nhinf,
/// initial_*), and which filters run.
struct InsGpsOptions {
  InsPropagatorOptions ins;
  KfOptions kf;
  EkfOptions ekf;
  UkfOptions ukf;
  SdreOptions sdre;
  NhinfOptions nhinf;
  std::vector<std::string> filters = {"kf", "ekf", "ukf", "sdre", "nhinf"};
  /// 1σ of the initial estimate's error (drawn once per run, the same for every filter).
  double initial_position_sigma = 2.0;      ///< [m]
  double initial_velocity_sigma = 0.3;      ///< [m/s]
  double initial_attitude_sigma_deg = 2.0;  ///< [deg]

  Status load(const ConfigNode& node);
};

/// Builds one filter by name (kf, ekf, ukf, sdre, nhinf).
Expected<std::unique_ptr<GpsAidedFilter>> makeFilter(const std::string& name,
                                                     const InsGpsOptions& o);

/// The data a run consumes (sim/gps_flight.h produces it).
struct FlightData {
  std::vector<ImuSample> imu;
  std::vector<GpsFix> gps;
  std::vector<StateVector> truth;  ///< at each IMU sample
};

/// Initial estimate x̂₀ = truth₀ + error drawn from the initial sigmas, and P₀ (diagonal).
void initialEstimate(const StateVector& truth0, const InsGpsOptions& o, uint64_t seed,
                     StateVector* x0, StateMatrix* P0);

struct FilterTrack {
  std::string name;
  std::vector<int64_t> t_us;          ///< every IMU sample
  std::vector<StateVector> estimate;  ///< at t_us
  std::vector<StateVector> sigma;     ///< √diag P at t_us
  std::vector<double> nees;           ///< NEES of the posterior at each applied fix
  std::vector<int64_t> nees_t_us;
  double compute_us = 0.0;  ///< total time in propagate() and update() [µs]
  int steps = 0;            ///< IMU steps
  int fixes = 0;            ///< fixes applied
};

/// Runs `filter` from (x0, P0) at imu[0] over the whole flight; fixes are applied at the IMU
/// sample with their time stamp.
Expected<FilterTrack> runFilter(GpsAidedFilter& filter, const FlightData& data,
                                const StateVector& x0, const StateMatrix& P0);

/// Per-axis error statistics of a track after `from_s` (to skip the initial transient).
struct ErrorStats {
  Eigen::Vector3d position_std;      ///< N E D [m]
  Eigen::Vector3d velocity_std;      ///< N E D [m/s] (R_BtoN v_B of estimate and truth)
  Eigen::Vector3d attitude_std_deg;  ///< φ θ ψ [deg]
  double position_rms = 0.0;         ///< RMS of ‖p̂ − p‖ [m]
  double position_max = 0.0;         ///< max ‖p̂ − p‖ [m]
  double mean_nees = 0.0;            ///< mean NEES over the fixes after from_s
  double us_per_step = 0.0;          ///< computation per IMU step [µs]
};
ErrorStats errorStats(const FilterTrack& track, const FlightData& data, double from_s);

/// Component-wise mean of several runs' statistics (the thesis's tables are "after many
/// tests"); empty input gives zeros.
ErrorStats meanStats(const std::vector<ErrorStats>& runs);

/// ‖p̂ − p‖ at each sample of the track.
std::vector<double> positionErrors(const FilterTrack& track, const FlightData& data);

/// Markdown tables (Table 3.2 analogue: position, velocity, attitude error std; Table 3.3
/// analogue: µs per step and relative to the EKF).
std::string markdownTables(const std::vector<FilterTrack>& tracks,
                           const std::vector<ErrorStats>& stats);

/// CSV of a track: t, estimate (9), truth (9), sigma (9), one row per `every` samples.
Status writeTrackCsv(const std::string& path, const FilterTrack& track, const FlightData& data,
                     int every);
/// CSV of the GPS fixes: t, p_N, v_N.
Status writeGpsCsv(const std::string& path, const std::vector<GpsFix>& fixes);

}  // namespace cvslam::insgps
