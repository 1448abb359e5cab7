// One S-VSLAM filter step (thesis §5.5, §5.7): INS prediction over one camera interval
// (20 Hz camera, 200 Hz IMU: 10 RK4 steps with Jet Jacobians) and one update with 20 stereo
// observations (4 rows each: 4×9 vehicle + 4×3 landmark blocks) over a state of 24 landmarks
// (n = 81). H blocks are random with the right sparsity; the numbers do not depend on them.
#include <benchmark/benchmark.h>

#include <random>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/ins/ins_propagator.h"
#include "cvslam/slam/stereo_second_order_noise.h"
#include "filter_fixtures.h"

namespace cvslam {
namespace {

/// The benchmarks time the thesis's Euler model (its state is a plain vector here).
InsPropagatorOptions eulerOptions() {
  InsPropagatorOptions o;
  o.attitude = vehicle::Attitude::kEuler;
  return o;
}

constexpr int kLandmarks = 24;
constexpr int kObservations = 20;

struct StepData {
  SlamState prior;
  MeasurementBatch batch;
  std::vector<ImuSample> imu;
  InsPropagator ins{eulerOptions()};

  StepData() {
    std::mt19937 rng(42);
    prior = test::randomSlamState(kLandmarks, rng);
    test::randomStereoBatch(prior, kObservations, rng, &batch);
    for (int k = 0; k <= 10; ++k) {
      ImuSample s;
      s.t_us = 5000 * k;
      s.gyro_B = {0.01 * k, -0.02, 0.05};
      s.accel_B = {0.3, -0.1, -9.7};
      imu.push_back(s);
    }
  }
};

UpdatePolicy policyFor(bool nhinf, double theta) {
  UpdatePolicy p = UpdatePolicy::ekf(0.999);
  if (nhinf) {
    p.theta = theta;
    p.measurement_noise_scale = 0.9;
    p.process_noise_scale = 0.85;
  }
  return p;
}

/// INS prediction over one camera interval (10 IMU steps); arg 1: with the 6 bias states.
void BM_InsPredict(benchmark::State& st) {
  const StepData d;
  InsPropagatorOptions o = eulerOptions();
  o.estimate_imu_bias = st.range(0) > 0;
  const InsPropagator ins(o);
  const Eigen::VectorXd x0 = Eigen::VectorXd::Zero(ins.stateSize());
  InsTransition tr;
  for (auto _ : st) {
    benchmark::DoNotOptimize(ins.propagate(x0, d.imu, &tr).ok());
  }
}
BENCHMARK(BM_InsPredict)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_CovariancePropagate(benchmark::State& st) {
  const StepData d;
  InsTransition tr;
  d.ins.propagate(d.prior.mean().head(9), d.imu, &tr);
  SlamState s = d.prior;
  for (auto _ : st) {
    CovarianceHelper::propagate(s, VariableKey::vehicle(0), tr.x, tr.Phi, tr.Qd,
                                UpdatePolicy::ekf());
    benchmark::DoNotOptimize(s.covariance().data());
  }
}
BENCHMARK(BM_CovariancePropagate)->Unit(benchmark::kMicrosecond);

/// Update only; arg 0: EKF, 1: NH∞ (admissible θ), 2: NH∞ with the eq. 3.40 fallback.
void BM_Update(benchmark::State& st) {
  const StepData d;
  const bool nhinf = st.range(0) > 0;
  const UpdatePolicy policy = policyFor(nhinf, st.range(0) == 2 ? 1e3 : 1e-3);
  SlamState s = d.prior;
  UpdateReport report;
  for (auto _ : st) {
    s = d.prior;
    CovarianceHelper::update(s, d.batch, policy, &report);
    benchmark::DoNotOptimize(s.covariance().data());
  }
  st.counters["theta_reduced"] = report.theta_reduced;
  st.counters["accepted"] = report.observations_accepted;
}
BENCHMARK(BM_Update)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

/// Times the EKF update of `prior` with 25 random stereo observations of its map landmarks.
void timeUpdate(benchmark::State& st, const SlamState& prior, std::mt19937& rng) {
  MeasurementBatch batch;
  test::randomStereoBatch(prior, 25, rng, &batch);
  const UpdatePolicy policy = UpdatePolicy::ekf(0.999);
  UpdateReport report;
  SlamState s = prior;
  for (auto _ : st) {
    s = prior;
    CovarianceHelper::update(s, batch, policy, &report);
    benchmark::DoNotOptimize(s.covariance().data());
  }
  st.counters["n"] = static_cast<double>(prior.size());
}

/// EKF update with 25 stereo observations over a map of range(0) landmarks (a room kept whole,
/// `map.kind: full`; docs/results/euroc_recorded.md "Map size"): the covariance update is
/// O(n² m) and dominates there. Arg 1: 0 the additive chart, 1 the invariant chart (its reset
/// moves every landmark's rows and columns: O(n²) more; docs/filter.md "Invariant error chart").
void BM_UpdateLargeMap(benchmark::State& st) {
  std::mt19937 rng(7);
  SlamState prior = test::randomSlamState(static_cast<int>(st.range(0)), rng);
  prior.setErrorChart(st.range(1) > 0 ? ErrorChart::kRightInvariant : ErrorChart::kAdditive);
  timeUpdate(st, prior, rng);
}
BENCHMARK(BM_UpdateLargeMap)->ArgsProduct({{100, 300, 700}, {0, 1}})->Unit(benchmark::kMillisecond);

/// The k-nearest map with held landmarks (`slam.held_landmarks`, Schmidt variables): 30 landmarks
/// in the map, range(0) held, 25 observations of the map's, invariant chart. Only the corrected
/// variables' rows and columns change (CovarianceHelper::update, step 4).
void BM_UpdateHeld(benchmark::State& st) {
  std::mt19937 rng(7);
  const int held = static_cast<int>(st.range(0));
  SlamState prior = test::randomSlamState(30 + held, rng);
  for (int k = 0; k < held; ++k) {
    const uint64_t id = 100u + 30u + static_cast<uint64_t>(k);
    CovarianceHelper::rekey(prior, VariableKey::landmark(id), VariableKey::heldLandmark(id));
  }
  prior.setErrorChart(ErrorChart::kRightInvariant);
  timeUpdate(st, prior, rng);
}
BENCHMARK(BM_UpdateHeld)->Arg(100)->Arg(300)->Unit(benchmark::kMillisecond);

/// The whole step: INS prediction, covariance propagation, update. Arg 0: EKF, 1: NH∞.
void BM_FilterStep(benchmark::State& st) {
  const StepData d;
  const UpdatePolicy policy = policyFor(st.range(0) > 0, 1e-3);
  SlamState s = d.prior;
  InsTransition tr;
  for (auto _ : st) {
    s = d.prior;
    d.ins.propagate(s.mean().head(9), d.imu, &tr);
    CovarianceHelper::propagate(s, VariableKey::vehicle(0), tr.x, tr.Phi, tr.Qd, policy);
    CovarianceHelper::update(s, d.batch, policy, nullptr);
    benchmark::DoNotOptimize(s.covariance().data());
  }
}
BENCHMARK(BM_FilterStep)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

/// The whole step (prediction, propagation, update with 20 stereo observations, invariant
/// chart) over a map of range(0) landmarks kept whole: how the cost grows with the map
/// (docs/filter.md "Cost against the map's size"). The propagation is O(n), the update and the
/// invariant chart's reset O(n²).
void BM_FilterStepMapSize(benchmark::State& st) {
  StepData d;
  std::mt19937 rng(7);
  d.prior = test::randomSlamState(static_cast<int>(st.range(0)), rng);
  d.prior.setErrorChart(ErrorChart::kRightInvariant);
  d.batch = MeasurementBatch();
  test::randomStereoBatch(d.prior, kObservations, rng, &d.batch);
  const UpdatePolicy policy = policyFor(false, 1e-3);
  SlamState s = d.prior;
  InsTransition tr;
  for (auto _ : st) {
    st.PauseTiming();
    s = d.prior;  // the copy of an n² covariance is not part of a step
    st.ResumeTiming();
    d.ins.propagate(s.mean().head(9), d.imu, &tr);
    CovarianceHelper::propagate(s, VariableKey::vehicle(0), tr.x, tr.Phi, tr.Qd, policy);
    CovarianceHelper::update(s, d.batch, policy, nullptr);
    benchmark::DoNotOptimize(s.covariance().data());
  }
  st.counters["state"] = static_cast<double>(d.prior.size());
}
BENCHMARK(BM_FilterStepMapSize)
    ->Arg(100)
    ->Arg(200)
    ->Arg(500)
    ->Arg(1000)
    ->Arg(2000)
    ->Unit(benchmark::kMillisecond);

/// The second-order terms of one stereo observation (ΔR and the mean; per observation with
/// features): the Hessians in (attitude, l − p) from 12 Jacobian evaluations. Arg 0: the mean
/// over the additive errors, 1: over the invariant error (the agents' chart).
void BM_StereoSecondOrderTerms(benchmark::State& st) {
  const StereoCamera camera;
  EstimatedPose pose;
  pose.p_BinN = Eigen::Vector3d(150.0, 20.0, -10.0);
  pose.R_BtoN = so3::exp(Eigen::Vector3d(0.05, -0.03, 0.8));
  const Eigen::Vector3d l = pose.p_BinN + Eigen::Vector3d(2.5, -1.5, 10.0);
  Eigen::Matrix<double, 12, 12> L = Eigen::Matrix<double, 12, 12>::Identity() * 0.05;
  L(11, 2) = 0.04;
  const Eigen::Matrix<double, 12, 12> P = L * L.transpose();
  const ErrorChart chart = st.range(0) > 0 ? ErrorChart::kRightInvariant : ErrorChart::kAdditive;
  for (auto _ : st) {
    const StereoSecondOrderTerms terms = stereoSecondOrderTerms(camera, pose, l, P, chart);
    benchmark::DoNotOptimize(terms.noise.data());
  }
}
BENCHMARK(BM_StereoSecondOrderTerms)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace cvslam

BENCHMARK_MAIN();
