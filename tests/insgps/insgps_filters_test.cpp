// The five INS/GPS filters on fixed-seed simulated flights (thesis §3.7.2): position-error
// bounds, NEES against χ² bounds over several seeds, and the GPS-outage flight's error growth
// and recovery. The flights are insgps_test_flights.h; the bounds are stated per test.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <ostream>
#include <string>
#include <vector>

#include "insgps/insgps_test_flights.h"

namespace cvslam::insgps {
namespace {

constexpr uint64_t kSeeds[] = {1, 2, 3};

/// Upper (1 − 0.01) quantile of the mean of n independent χ²_k variables, by Wilson–Hilferty
/// on χ²_{nk}: (nk)(1 − 2/(9nk) + z √(2/(9nk)))³ / n, z = 2.326.
double meanChi2Upper(int k, int n) {
  const double nk = static_cast<double>(k) * n;
  const double a = 2.0 / (9.0 * nk);
  return nk * std::pow(1.0 - a + 2.326 * std::sqrt(a), 3.0) / n;
}

struct SeedResult {
  ErrorStats stats;
  std::vector<double> nees;
};

SeedResult runOn(const std::string& filter_name, const InsGpsOptions& o, const FlightData& data,
                 uint64_t seed, double from_s) {
  StateVector x0;
  StateMatrix P0;
  initialEstimate(data.truth.front(), o, seed, &x0, &P0);
  auto filter = makeFilter(filter_name, o);
  EXPECT_TRUE(filter.ok());
  auto track = runFilter(*filter.value(), data, x0, P0);
  EXPECT_TRUE(track.ok()) << track.status().message();
  SeedResult r;
  r.stats = errorStats(*track, data, from_s);
  const auto from_us = static_cast<int64_t>(1e6 * from_s);
  for (std::size_t i = 0; i < track->nees.size(); ++i)
    if (track->nees_t_us[i] >= from_us) r.nees.push_back(track->nees[i]);
  return r;
}

struct FilterBound {
  std::string name;
  double position_rms;  ///< bound on the RMS position error after 10 s, each seed [m]
  double nees_factor;   ///< the mean NEES must stay below factor × the χ² 99 % bound
};

// KF and EKF-family: consistent filters, factor 1. The bounds on the position RMS are about
// 3× what they reach (0.3–0.4 m; the GPS alone gives σ ≈ 1.5–3 m per axis), so a broken
// correction or Jacobian fails them. SDRE: its P is the steady state of the frozen SDC pair,
// not the covariance of its actual error (and it cannot correct yaw, sdc_factorisation.h),
// so its NEES is only required within 10× the χ² bound (it reaches ~7×), and its position
// RMS (~1 m) within 3 m.
const FilterBound kBounds[] = {{"kf", 1.5, 1.0},
                               {"ekf", 1.2, 1.0},
                               {"ukf", 1.2, 1.0},
                               {"nhinf", 1.2, 1.0},
                               {"sdre", 3.0, 10.0}};

void PrintTo(const FilterBound& b, std::ostream* os) {
  *os << b.name;
}

class InsGpsFilters : public ::testing::TestWithParam<FilterBound> {};

TEST_P(InsGpsFilters, SharpFlightPositionErrorAndNees) {
  const FilterBound b = GetParam();
  InsGpsOptions o;
  // The KF's linear error model is linearised along the free INS: with small initial errors
  // it stays valid over the 40 s (larger ones: docs/results/thesis_ch3.md).
  o.initial_attitude_sigma_deg = 0.5;
  std::vector<double> nees;
  for (uint64_t seed : kSeeds) {
    const FlightData data = test::simulate(test::sharpFlightYaml(seed));
    const SeedResult r = runOn(b.name, o, data, seed, 10.0);
    EXPECT_LT(r.stats.position_rms, b.position_rms) << b.name << " seed " << seed;
    nees.insert(nees.end(), r.nees.begin(), r.nees.end());
  }
  ASSERT_GT(nees.size(), 300u);
  const double mean = std::accumulate(nees.begin(), nees.end(), 0.0) / nees.size();
  // NEES at consecutive fixes are correlated, so the bound on the mean is taken with the
  // number of seeds × 10 effective samples rather than every fix (conservative).
  const double bound = meanChi2Upper(kStateSize, 10 * static_cast<int>(std::size(kSeeds)));
  std::printf("%s: mean NEES %.2f over %zu fixes, bound %.2f\n", b.name.c_str(), mean, nees.size(),
              b.nees_factor * bound);
  EXPECT_LT(mean, b.nees_factor * bound) << b.name;
  // And not absurdly pessimistic either (a P that is far too large also passes the upper test).
  EXPECT_GT(mean, 0.2 * kStateSize) << b.name;
}

INSTANTIATE_TEST_SUITE_P(AllFilters, InsGpsFilters, ::testing::ValuesIn(kBounds),
                         [](const auto& param_info) { return param_info.param.name; });

TEST(InsGpsOutage, ErrorGrowsDuringTheOutageAndRecoversAfter) {
  const FlightData data = test::simulate(test::outageFlightYaml(4));
  InsGpsOptions o;
  for (const std::string name : {"kf", "ekf", "ukf", "sdre", "nhinf"}) {
    StateVector x0;
    StateMatrix P0;
    initialEstimate(data.truth.front(), o, 4, &x0, &P0);
    auto filter = makeFilter(name, o);
    ASSERT_TRUE(filter.ok());
    auto track = runFilter(*filter.value(), data, x0, P0);
    ASSERT_TRUE(track.ok()) << track.status().message();
    const std::vector<double> err = positionErrors(*track, data);
    auto meanOver = [&](double a, double b) {
      double s = 0.0;
      int n = 0;
      for (std::size_t k = 0; k < err.size(); ++k) {
        const double t = 1e-6 * static_cast<double>(track->t_us[k]);
        if (t >= a && t < b) {
          s += err[k];
          ++n;
        }
      }
      return s / n;
    };
    const double before = meanOver(20.0, 30.0);      // converged, with GPS
    const double end_outage = meanOver(49.0, 50.0);  // last second of the 20 s outage
    const double after = meanOver(70.0, 90.0);       // 20 s after the GPS returns
    EXPECT_GT(end_outage, 2.0 * before) << name;     // coasting on the INS drifts
    EXPECT_LT(after, 0.5 * end_outage) << name;      // the fixes pull it back
    // To about the pre-outage accuracy; the open-loop KF less so: its linear error model is
    // linearised along the free INS, which drifted further during the outage.
    EXPECT_LT(after, before + (name == "kf" ? 2.5 : 1.0)) << name;
    // The filter knows it is coasting: its position σ grows over the outage.
    if (name != "sdre") {
      const auto k30 = static_cast<std::size_t>(30.0 * 200.0);
      const auto k50 = static_cast<std::size_t>(49.9 * 200.0);
      EXPECT_GT(track->sigma[k50].head<3>().norm(), 2.0 * track->sigma[k30].head<3>().norm())
          << name;
    }
  }
}

TEST(InsGpsFilters, YawNearPiIsAveragedAcrossTheWrap) {
  // Yaw starts at π − 0.01 and turns at 0.5 rad/s, crossing ±π: the UKF's sigma points straddle
  // the wrap; its mean and covariance must match the EKF's (a naive average would give ~0).
  InsGpsOptions o;
  GpsAidedEkf ekf(o.ins, o.ekf);
  GpsAidedUkf ukf(o.ins, o.ukf);
  StateVector x0;
  x0 << 0.0, 0.0, -30.0, 5.0, 0.0, 0.0, 0.0, 0.0, M_PI - 0.01;
  StateMatrix P0 = StateMatrix::Identity();
  P0.diagonal().segment<3>(6).setConstant(std::pow(0.05, 2));
  ekf.initialize(x0, P0, 0);
  ukf.initialize(x0, P0, 0);
  ImuSample s0;
  s0.gyro_B = Eigen::Vector3d(0.0, 0.0, 0.5);
  s0.accel_B = Eigen::Vector3d(0.0, 2.5, -9.81);  // centripetal: v × ω
  for (int k = 1; k <= 200; ++k) {
    ImuSample s1 = s0;
    s1.t_us = 5000 * k;
    ASSERT_TRUE(ekf.propagate(s0, s1).ok());
    ASSERT_TRUE(ukf.propagate(s0, s1).ok());
    s0 = s1;
  }
  EXPECT_LT(ukf.state()(8), -M_PI + 0.6);  // crossed the wrap
  const StateVector d = stateDifference(ukf.state(), ekf.state());
  EXPECT_LT(std::abs(d(8)), 0.005);
  // The rest differs by the UKF's second-order terms (E[cos δ] < 1 of the 0.05 rad attitude σ).
  EXPECT_LT(d.norm(), 0.1);
  EXPECT_NEAR(std::sqrt(ukf.covariance()(8, 8)), std::sqrt(ekf.covariance()(8, 8)), 0.005);
}

TEST(InsGpsFilters, ClosedLoopKfRecoversWhatTheOpenLoopKfLoses) {
  // §3.3 vs §3.4: the open-loop KF linearises along the free INS, which an initial attitude
  // error (σ 5°) makes drift far; folding δx̂ into the INS at every fix (reset_interval_s) keeps the
  // linearisation point near the truth, and the KF then matches the EKF.
  const FlightData data = test::simulate(test::sharpFlightYaml(2, 90.0));
  InsGpsOptions o;
  o.initial_attitude_sigma_deg = 5.0;
  const double open = runOn("kf", o, data, 2, 10.0).stats.position_rms;
  const double ekf = runOn("ekf", o, data, 2, 10.0).stats.position_rms;
  o.kf.reset_interval_s = 0.1;
  const double closed = runOn("kf", o, data, 2, 10.0).stats.position_rms;
  std::printf("position RMS: open-loop KF %.3f, closed-loop KF %.3f, EKF %.3f m\n", open, closed,
              ekf);
  EXPECT_GT(open, 1.5 * ekf);
  EXPECT_LT(closed, 1.1 * ekf);
}

TEST(InsGpsRun, TablesNameEveryFilterAndMeasureTime) {
  const FlightData data = test::simulate(test::sharpFlightYaml(1));
  InsGpsOptions o;
  StateVector x0;
  StateMatrix P0;
  initialEstimate(data.truth.front(), o, 1, &x0, &P0);
  std::vector<FilterTrack> tracks;
  std::vector<ErrorStats> stats;
  for (const std::string& name : o.filters) {
    auto f = makeFilter(name, o);
    ASSERT_TRUE(f.ok());
    auto track = runFilter(*f.value(), data, x0, P0);
    ASSERT_TRUE(track.ok());
    EXPECT_EQ(track->estimate.size(), data.imu.size());
    EXPECT_EQ(track->fixes, static_cast<int>(data.gps.size()));
    stats.push_back(errorStats(*track, data, 0.0));
    EXPECT_GT(stats.back().us_per_step, 0.0);
    tracks.push_back(std::move(track.value()));
  }
  const std::string tables = markdownTables(tracks, stats);
  for (const std::string& name : o.filters)
    EXPECT_NE(tables.find("| " + name + " |"), std::string::npos) << tables;
  EXPECT_FALSE(makeFilter("pf", o).ok());
}

TEST(InsGpsOptions, LoadsFromYamlAndRejectsBadValues) {
  auto cfg = ConfigNode::fromString(R"(
run: [ekf, sdre]
initial_position_sigma: 3.0
ekf: {joseph_form: false, innovation_gate: 22.5}
sdre: {alpha: 0.25, riccati_discount: 0.99}
nhinf: {gamma: 5.0}
)",
                                    "filters.yaml");
  ASSERT_TRUE(cfg.ok());
  InsGpsOptions o;
  ASSERT_TRUE(o.load(*cfg).ok());
  ASSERT_TRUE(cfg->finish().ok()) << cfg->finish().message();
  EXPECT_EQ(o.filters, (std::vector<std::string>{"ekf", "sdre"}));
  EXPECT_DOUBLE_EQ(o.initial_position_sigma, 3.0);
  EXPECT_FALSE(o.ekf.joseph_form);
  EXPECT_DOUBLE_EQ(o.ekf.innovation_gate, 22.5);
  EXPECT_DOUBLE_EQ(o.sdre.alpha, 0.25);
  EXPECT_DOUBLE_EQ(o.sdre.riccati_discount, 0.99);
  EXPECT_DOUBLE_EQ(o.nhinf.gamma, 5.0);

  const char* bad[] = {
      "run: [ekf, pf]",  "sdre: {riccati_discount: 1.5}", "nhinf: {gamma: 0.01}",
      "ukf: {alpha: 0}", "kf: {reset_interval_s: -1}",    "initial_attitude_sigma_deg: 0"};
  const char* key[] = {"run",   "riccati_discount", "gamma",
                       "alpha", "reset_interval_s", "initial_attitude_sigma_deg"};
  for (std::size_t i = 0; i < std::size(bad); ++i) {
    auto c = ConfigNode::fromString(bad[i], "filters.yaml");
    ASSERT_TRUE(c.ok());
    InsGpsOptions oi;
    const Status st = oi.load(*c);
    ASSERT_FALSE(st.ok()) << bad[i];
    EXPECT_NE(st.message().find(key[i]), std::string::npos) << st.message();
  }
}

}  // namespace
}  // namespace cvslam::insgps
