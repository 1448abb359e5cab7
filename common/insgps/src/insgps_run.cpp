#include "cvslam/insgps/insgps_run.h"

#include <Eigen/Cholesky>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "cvslam/core/random.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/io/config_node.h"

namespace cvslam::insgps {

namespace {

const std::vector<std::string>& filterNames() {
  static const std::vector<std::string> names = {"kf", "ekf", "ukf", "sdre", "nhinf"};
  return names;
}

Eigen::Vector3d velocityNed(const StateVector& x) {
  const Eigen::Vector3d euler = x.segment<3>(vehicle::kAttitude);
  return rotationBodyToNav(euler) * x.segment<3>(vehicle::kVelocity);
}

/// Standard deviation per component of a list of vectors.
Eigen::Vector3d stdOf(const std::vector<Eigen::Vector3d>& v) {
  if (v.empty()) return Eigen::Vector3d::Zero();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum2 = Eigen::Vector3d::Zero();
  for (const auto& e : v) {
    sum += e;
    sum2 += e.cwiseAbs2();
  }
  const double n = static_cast<double>(v.size());
  return (sum2 / n - (sum / n).cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
}

}  // namespace

Status InsGpsOptions::load(const ConfigNode& node) {
  ins.load(node.child("ins"));
  kf.load(node.child("kf"));
  ekf.load(node.child("ekf"));
  ukf.load(node.child("ukf"));
  sdre.load(node.child("sdre"));
  nhinf.load(node.child("nhinf"));
  node.get("run", filters);
  for (const std::string& f : filters) {
    bool known = false;
    for (const std::string& n : filterNames()) known = known || n == f;
    node.check(known, "run", "unknown filter '" + f + "' (kf, ekf, ukf, sdre, nhinf)");
  }
  node.check(!filters.empty(), "run", "must name at least one filter");
  node.get("initial_position_sigma", initial_position_sigma);
  node.get("initial_velocity_sigma", initial_velocity_sigma);
  node.get("initial_attitude_sigma_deg", initial_attitude_sigma_deg);
  node.check(initial_position_sigma > 0.0, "initial_position_sigma", "must be > 0");
  node.check(initial_velocity_sigma > 0.0, "initial_velocity_sigma", "must be > 0");
  node.check(initial_attitude_sigma_deg > 0.0, "initial_attitude_sigma_deg", "must be > 0");
  return node.status();
}

Expected<std::unique_ptr<GpsAidedFilter>> makeFilter(const std::string& name,
                                                     const InsGpsOptions& o) {
  std::unique_ptr<GpsAidedFilter> f;
  if (name == "kf") f = std::make_unique<GpsAidedKf>(o.ins, o.kf);
  if (name == "ekf") f = std::make_unique<GpsAidedEkf>(o.ins, o.ekf);
  if (name == "ukf") f = std::make_unique<GpsAidedUkf>(o.ins, o.ukf);
  if (name == "sdre") f = std::make_unique<SdreFilter>(o.ins, o.sdre);
  if (name == "nhinf") f = std::make_unique<NhinfGpsFilter>(o.ins, o.nhinf);
  if (!f) return Status::Error("unknown filter '" + name + "' (kf, ekf, ukf, sdre, nhinf)");
  return f;
}

void initialEstimate(const StateVector& truth0, const InsGpsOptions& o, uint64_t seed,
                     StateVector* x0, StateMatrix* P0) {
  StateVector sigma;
  const double att = o.initial_attitude_sigma_deg * M_PI / 180.0;
  sigma << Eigen::Vector3d::Constant(o.initial_position_sigma),
      Eigen::Vector3d::Constant(o.initial_velocity_sigma), Eigen::Vector3d::Constant(att);
  Rng rng(deriveSeed(seed, 0, RngStream::kInitialState));
  StateVector err;
  for (int i = 0; i < kStateSize; ++i) err(i) = sigma(i) * rng.gaussian();
  *x0 = wrapYaw(truth0 + err);
  *P0 = sigma.cwiseAbs2().asDiagonal();
}

Expected<FilterTrack> runFilter(GpsAidedFilter& filter, const FlightData& data,
                                const StateVector& x0, const StateMatrix& P0) {
  if (data.imu.size() < 2 || data.truth.size() != data.imu.size())
    return Status::Error("flight has fewer than 2 IMU samples or truth of the wrong size");
  using Clock = std::chrono::steady_clock;
  FilterTrack track;
  track.name = filter.name();
  filter.initialize(x0, P0, data.imu.front().t_us);
  std::size_t next_fix = 0;
  while (next_fix < data.gps.size() && data.gps[next_fix].t_us < data.imu.front().t_us) ++next_fix;
  auto record = [&](std::size_t k) {
    track.t_us.push_back(data.imu[k].t_us);
    track.estimate.push_back(filter.state());
    track.sigma.push_back(filter.covariance().diagonal().cwiseMax(0.0).cwiseSqrt());
  };
  double elapsed_us = 0.0;
  for (std::size_t k = 0; k < data.imu.size(); ++k) {
    const auto t0 = Clock::now();
    if (k > 0) {
      Status st = filter.propagate(data.imu[k - 1], data.imu[k]);
      if (!st.ok()) return Status::Error(filter.name() + ": " + st.message());
      ++track.steps;
    }
    bool fixed = false;
    while (next_fix < data.gps.size() && data.gps[next_fix].t_us <= data.imu[k].t_us) {
      Status st = filter.update(data.gps[next_fix]);
      if (!st.ok()) return Status::Error(filter.name() + ": " + st.message());
      ++next_fix;
      ++track.fixes;
      fixed = true;
    }
    elapsed_us += std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
    if (fixed) {
      const StateVector e = stateDifference(data.truth[k], filter.state());
      const StateMatrix P = filter.covariance();
      track.nees.push_back(e.dot(P.ldlt().solve(e)));
      track.nees_t_us.push_back(data.imu[k].t_us);
    }
    if (!filter.state().allFinite())
      return Status::Error(filter.name() + ": estimate not finite at t = " +
                           std::to_string(1e-6 * static_cast<double>(data.imu[k].t_us)) + " s");
    record(k);
  }
  track.compute_us = elapsed_us;
  return track;
}

ErrorStats meanStats(const std::vector<ErrorStats>& runs) {
  ErrorStats m;
  m.position_std.setZero();
  m.velocity_std.setZero();
  m.attitude_std_deg.setZero();
  if (runs.empty()) return m;
  const double w = 1.0 / static_cast<double>(runs.size());
  for (const ErrorStats& r : runs) {
    m.position_std += w * r.position_std;
    m.velocity_std += w * r.velocity_std;
    m.attitude_std_deg += w * r.attitude_std_deg;
    m.position_rms += w * r.position_rms;
    m.position_max += w * r.position_max;
    m.mean_nees += w * r.mean_nees;
    m.us_per_step += w * r.us_per_step;
  }
  return m;
}

std::vector<double> positionErrors(const FilterTrack& track, const FlightData& data) {
  std::vector<double> out;
  for (std::size_t k = 0; k < track.estimate.size(); ++k)
    out.push_back((track.estimate[k] - data.truth[k]).head<3>().norm());
  return out;
}

ErrorStats errorStats(const FilterTrack& track, const FlightData& data, double from_s) {
  const auto from_us = static_cast<int64_t>(1e6 * from_s);
  std::vector<Eigen::Vector3d> ep, ev, ea;
  ErrorStats s;
  double sum_sq = 0.0;
  for (std::size_t k = 0; k < track.estimate.size(); ++k) {
    if (track.t_us[k] < from_us) continue;
    const StateVector e = stateDifference(track.estimate[k], data.truth[k]);
    ep.push_back(e.head<3>());
    ev.push_back(velocityNed(track.estimate[k]) - velocityNed(data.truth[k]));
    ea.push_back(e.segment<3>(vehicle::kAttitude) * 180.0 / M_PI);
    sum_sq += e.head<3>().squaredNorm();
    s.position_max = std::max(s.position_max, e.head<3>().norm());
  }
  s.position_std = stdOf(ep);
  s.velocity_std = stdOf(ev);
  s.attitude_std_deg = stdOf(ea);
  s.position_rms = ep.empty() ? 0.0 : std::sqrt(sum_sq / static_cast<double>(ep.size()));
  int n = 0;
  for (std::size_t i = 0; i < track.nees.size(); ++i) {
    if (track.nees_t_us[i] < from_us) continue;
    s.mean_nees += track.nees[i];
    ++n;
  }
  s.mean_nees = n > 0 ? s.mean_nees / n : 0.0;
  s.us_per_step = track.steps > 0 ? track.compute_us / track.steps : 0.0;
  return s;
}

std::string markdownTables(const std::vector<FilterTrack>& tracks,
                           const std::vector<ErrorStats>& stats) {
  std::ostringstream os;
  os << std::fixed;
  os << "| filter | σx (m) | σy (m) | σz (m) | σvN (m/s) | σvE (m/s) | σvD (m/s) | σφ (°) | "
        "σθ (°) | σψ (°) | pos RMS (m) | max (m) | mean NEES |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    const ErrorStats& s = stats[i];
    os << "| " << tracks[i].name << std::setprecision(3);
    for (int a = 0; a < 3; ++a) os << " | " << s.position_std(a);
    for (int a = 0; a < 3; ++a) os << " | " << s.velocity_std(a);
    for (int a = 0; a < 3; ++a) os << " | " << s.attitude_std_deg(a);
    os << " | " << s.position_rms << " | " << s.position_max << " | " << std::setprecision(2)
       << s.mean_nees << " |\n";
  }
  double ekf_us = 0.0;
  for (std::size_t i = 0; i < tracks.size(); ++i)
    if (tracks[i].name == "ekf") ekf_us = stats[i].us_per_step;
  os << "\n| filter | µs per IMU step | relative to EKF | ms per 100 steps (Table 3.3 unit) |\n"
     << "|---|---|---|---|\n";
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    os << "| " << tracks[i].name << std::setprecision(1) << " | " << stats[i].us_per_step << " | "
       << std::setprecision(2) << (ekf_us > 0.0 ? stats[i].us_per_step / ekf_us : 0.0) << " | "
       << std::setprecision(4) << 100.0 * stats[i].us_per_step * 1e-3 << " |\n";
  }
  return os.str();
}

Status writeTrackCsv(const std::string& path, const FilterTrack& track, const FlightData& data,
                     int every) {
  std::ofstream out(path);
  if (!out) return Status::Error("cannot write " + path);
  out << "t,x,y,z,u,v,w,phi,theta,psi,x_true,y_true,z_true,u_true,v_true,w_true,phi_true,"
         "theta_true,psi_true,sx,sy,sz,su,sv,sw,sphi,stheta,spsi\n";
  out.precision(9);
  const std::size_t step = static_cast<std::size_t>(std::max(1, every));
  for (std::size_t k = 0; k < track.estimate.size(); k += step) {
    out << 1e-6 * static_cast<double>(track.t_us[k]);
    for (int i = 0; i < kStateSize; ++i) out << ',' << track.estimate[k](i);
    for (int i = 0; i < kStateSize; ++i) out << ',' << data.truth[k](i);
    for (int i = 0; i < kStateSize; ++i) out << ',' << track.sigma[k](i);
    out << '\n';
  }
  return out ? Status::Ok() : Status::Error("write failed: " + path);
}

Status writeGpsCsv(const std::string& path, const std::vector<GpsFix>& fixes) {
  std::ofstream out(path);
  if (!out) return Status::Error("cannot write " + path);
  out << "t,x,y,z,vn,ve,vd\n";
  out.precision(9);
  for (const GpsFix& f : fixes) {
    out << 1e-6 * static_cast<double>(f.t_us);
    for (int i = 0; i < 3; ++i) out << ',' << f.p_N(i);
    for (int i = 0; i < 3; ++i) out << ',' << f.v_N(i);
    out << '\n';
  }
  return out ? Status::Ok() : Status::Error("write failed: " + path);
}

}  // namespace cvslam::insgps
