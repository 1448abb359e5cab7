// The iterated EKF update (CovarianceHelper::iteratedUpdate), the state difference it rests on,
// and loop closing through it (loop_closer.h): the loop's correction comes through the gain, its
// joint NIS gate refuses a drift the covariance cannot explain, and over Monte-Carlo draws of
// the drift the closed loop is consistent.

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

#include "cvslam/filter/chi_square.h"
#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/ins/vehicle_state_layout.h"
#include "cvslam/slam/landmark_archive.h"
#include "cvslam/slam/landmark_book.h"
#include "cvslam/slam/landmark_initialiser.h"
#include "cvslam/slam/loop_closer.h"
#include "cvslam/slam/stereo_updater.h"

namespace cvslam {
namespace {

constexpr int64_t kUsPerS = 1000000;

// ---- The update on a point seen by range and bearings (a strongly nonlinear h) ----

const VariableKey kPoint = VariableKey::landmark(7);

/// Range and two bearings of p from the origin, and range from (20, 0, 0).
Eigen::Vector4d rangeBearing(const Eigen::Vector3d& p) {
  return {p.norm(), std::atan2(p.y(), p.x()), std::asin(p.z() / p.norm()),
          (p - Eigen::Vector3d(20.0, 0.0, 0.0)).norm()};
}

Eigen::Matrix<double, 4, 3> rangeBearingJacobian(const Eigen::Vector3d& p) {
  Eigen::Matrix<double, 4, 3> H;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d(i) = 1e-6;
    H.col(i) = (rangeBearing(p + d) - rangeBearing(p - d)) / 2e-6;
  }
  return H;
}

const Eigen::Matrix4d kR = Eigen::Vector4d(0.01, 1e-6, 1e-6, 0.01).asDiagonal();

SlamState pointState(const Eigen::Vector3d& mean, double sigma) {
  SlamState s;
  EXPECT_TRUE(
      CovarianceHelper::addVariable(s, kPoint, mean, Eigen::Matrix3d::Identity() * sigma * sigma)
          .ok());
  return s;
}

CovarianceHelper::Linearisation pointMeasurement(const Eigen::Vector4d& z) {
  return [z](const SlamState& at, MeasurementBatch* b) {
    const StateVariable* v = at.find(kPoint);
    const Eigen::Vector3d p = at.value(*v);
    b->reset(at.size(), 4);
    const int g = b->addObservation(z - rangeBearing(p), kR);
    b->setJacobian(g, *v, rangeBearingJacobian(p));
    return Status::Ok();
  };
}

/// The MAP estimate of the point by Gauss–Newton run to convergence, independently.
Eigen::Vector3d mapEstimate(const Eigen::Vector3d& prior, double sigma, const Eigen::Vector4d& z) {
  Eigen::Vector3d p = prior;
  const Eigen::Matrix4d W = kR.inverse();
  for (int i = 0; i < 100; ++i) {
    const Eigen::Matrix<double, 4, 3> H = rangeBearingJacobian(p);
    const Eigen::Matrix3d A = H.transpose() * W * H + Eigen::Matrix3d::Identity() / (sigma * sigma);
    const Eigen::Vector3d g =
        H.transpose() * W * (z - rangeBearing(p)) - (p - prior) / (sigma * sigma);
    p += A.ldlt().solve(g);
  }
  return p;
}

/// The point after one plain EKF update (CovarianceHelper::update) from N(prior, σ² I).
SlamState ekfUpdate(const Eigen::Vector3d& prior, double sigma, const Eigen::Vector4d& z) {
  SlamState s = pointState(prior, sigma);
  MeasurementBatch batch;
  EXPECT_TRUE(pointMeasurement(z)(s, &batch).ok());
  EXPECT_TRUE(CovarianceHelper::update(s, batch, UpdatePolicy::ekf(), nullptr).ok());
  return s;
}

/// CovarianceHelper::iteratedUpdate of `state` with z, linearised first at `start`.
UpdateReport iterate(SlamState& state, const SlamState& start, const Eigen::Vector4d& z,
                     int iterations, double joint_gate_probability = 0.0) {
  IteratedUpdateOptions o;
  o.max_iterations = iterations;
  o.joint_gate_probability = joint_gate_probability;
  MeasurementBatch batch;
  UpdateReport report;
  EXPECT_TRUE(CovarianceHelper::iteratedUpdate(state, start, pointMeasurement(z), o,
                                               UpdatePolicy::ekf(), &batch, &report)
                  .ok());
  return report;
}

TEST(IteratedUpdate, OneIterationAtThePriorIsTheEkfUpdate) {
  const Eigen::Vector3d prior(10.0, 1.0, 2.0);
  const Eigen::Vector4d z = rangeBearing(Eigen::Vector3d(10.5, 0.2, 2.4));
  const SlamState ekf = ekfUpdate(prior, 1.0, z);
  SlamState iterated = pointState(prior, 1.0);
  EXPECT_EQ(iterate(iterated, iterated, z, 1).iterations, 1);
  EXPECT_LT((iterated.mean() - ekf.mean()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((iterated.covariance() - ekf.covariance()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(IteratedUpdate, ReachesTheMapEstimateFromAFarLinearisationPoint) {
  // The prior is 8 m (4σ) off; one EKF step linearised there lands far from the optimum.
  const Eigen::Vector3d prior(10.0, 6.0, 3.0), truth(6.0, -0.5, 1.0);
  const Eigen::Vector4d z = rangeBearing(truth);
  const Eigen::Vector3d expected = mapEstimate(prior, 2.0, z);
  const SlamState ekf = ekfUpdate(prior, 2.0, z);
  SlamState iterated = pointState(prior, 2.0);
  // Started at a rough guess near the truth (as the loop closer starts at its alignment).
  const SlamState start = pointState(truth + Eigen::Vector3d(0.3, -0.2, 0.1), 2.0);
  const UpdateReport report = iterate(iterated, start, z, 10);
  const Eigen::Vector3d p_ekf = ekf.mean(), p_iterated = iterated.mean();
  EXPECT_GT((p_ekf - expected).norm(), 0.1) << "the test's h is not nonlinear enough";
  EXPECT_LT((p_iterated - expected).norm(), 1e-6) << p_iterated.transpose();
  EXPECT_LT(report.iterations, 10);
  // The covariance is the EKF's at the optimum: (P⁻¹ + Hᵀ R⁻¹ H)⁻¹ with H there.
  const Eigen::Matrix<double, 4, 3> H = rangeBearingJacobian(expected);
  const Eigen::Matrix3d P_expected =
      (Eigen::Matrix3d::Identity() / 4.0 + H.transpose() * kR.inverse() * H).inverse();
  EXPECT_LT((iterated.covariance() - P_expected).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(IteratedUpdate, TheJointGateRefusesWhatThePriorCannotExplainAndLeavesTheState) {
  const Eigen::Vector3d prior(10.0, 6.0, 3.0);
  // 30 m off a prior of σ 0.5 m: the joint NIS is thousands.
  const Eigen::Vector4d z = rangeBearing(Eigen::Vector3d(-15.0, 10.0, 3.0));
  SlamState state = pointState(prior, 0.5);
  const SlamState before = state;
  const UpdateReport report = iterate(state, state, z, 5, 0.9999);
  EXPECT_TRUE(report.rejected_jointly);
  EXPECT_GT(report.nis, chiSquareQuantile(0.9999, 4));
  EXPECT_EQ(state.mean(), before.mean());
  EXPECT_EQ(state.covariance(), before.covariance());
  // A measurement the prior explains passes the same gate.
  const Eigen::Vector4d z_near = rangeBearing(prior + Eigen::Vector3d(0.4, -0.3, 0.2));
  EXPECT_FALSE(iterate(state, state, z_near, 5, 0.9999).rejected_jointly);
  EXPECT_NE(state.mean(), before.mean());
}

TEST(StateDifference, InvertsTheVehicleCorrectionInBothAttitudeModels) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 0.3);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd x_b(vehicle::kSizeWithBias), dx(vehicle::kSizeWithBias);
    for (int i = 0; i < x_b.size(); ++i) x_b(i) = n(rng), dx(i) = n(rng);
    x_b(vehicle::kAttitude + 2) = 3.0;  // yaw near π: the correction may wrap
    // Euler angles.
    Eigen::VectorXd x_a = x_b;
    vehicle_model::correct(x_a, dx, nullptr);
    EXPECT_LT((vehicle_model::difference(x_a, nullptr, x_b, nullptr) - dx).norm(), 1e-12);
    // Rotation error state: δθ folded into the nominal.
    Eigen::VectorXd y_b = x_b;
    y_b.segment<3>(vehicle::kAttitude).setZero();
    const Eigen::Quaterniond q_b(so3::exp<double>(x_b.segment<3>(vehicle::kAttitude)));
    Eigen::Quaterniond q_a = q_b;
    Eigen::VectorXd y_a = y_b;
    vehicle_model::correct(y_a, dx, &q_a);
    EXPECT_LT((vehicle_model::difference(y_a, &q_a, y_b, &q_b) - dx).norm(), 1e-9);
  }
}

// ---- Loop closing through the iterated update ----

/// A vehicle 10 m above a patch of ground with 12 landmarks, level, heading 0.3 rad.
struct LoopScene {
  VariableKey key = VariableKey::vehicle(1);
  StereoCamera camera;
  SlamOptions options;
  StereoCamera::Vector9d truth = StereoCamera::Vector9d::Zero();
  std::vector<Eigen::Vector3d> landmarks;
  LoopScene() {
    options.max_new_landmarks_per_frame = 12;  // all of them mapped in the first frame
    truth.segment<3>(vehicle::kPosition) = Eigen::Vector3d(5.0, -3.0, -10.0);
    truth.segment<3>(vehicle::kVelocity) = Eigen::Vector3d(2.0, 0.0, 0.0);
    truth.segment<3>(vehicle::kAttitude) = Eigen::Vector3d(0.01, -0.02, 0.3);
    for (int i = 0; i < 12; ++i) {
      const double a = 0.7 * i, r = 0.6 + 0.17 * i;
      landmarks.emplace_back(5.0 + r * std::cos(a), -3.0 + r * std::sin(a), 0.3 * std::sin(i));
    }
  }
  /// Observations of every landmark from the pose `seen_from`, pixel noise of σ `sigma_px`.
  StereoFrameObservations observe(const StereoCamera::Vector9d& seen_from, int64_t t_us,
                                  double sigma_px, std::mt19937& rng) const {
    std::normal_distribution<double> noise(0.0, sigma_px);
    StereoFrameObservations f;
    f.t_us = t_us;
    for (std::size_t k = 0; k < landmarks.size(); ++k) {
      StereoObservation o;
      o.landmark_id = 100 + static_cast<int64_t>(k);
      o.index = static_cast<uint32_t>(o.landmark_id);
      o.z = camera.project(seen_from, landmarks[k]);
      for (int i = 0; i < 4; ++i) o.z(i) += noise(rng);
      f.observations.push_back(o);
    }
    return f;
  }
};

/// The state of one loop: the vehicle starts with error e0 ~ N(0, P0) and maps the landmarks
/// at t = 0; 40 s later it has drifted by d ~ N(0, Q) (the covariance grows by Q) and sees
/// them again from its true pose, scene.truth − d.
struct LoopRun {
  SlamState state;
  LandmarkBook book;
  LoopReport report;
  Eigen::VectorXd error_before;  // estimate − truth, vehicle block (Euler layout)
};

LoopRun closeLoop(const LoopScene& scene, const Eigen::MatrixXd& P0, const Eigen::MatrixXd& Q,
                  const Eigen::VectorXd& e0, const Eigen::VectorXd& d, std::mt19937& rng) {
  LoopRun run;
  const Eigen::VectorXd x_est = scene.truth + e0;
  EXPECT_TRUE(CovarianceHelper::addVariable(run.state, scene.key, x_est, P0).ok());
  run.book.setVehicleYawDirection(
      vehicle_model::yawDirection(EstimatedPose::fromEuler(x_est), vehicle::kSizeNoBias));
  const double sigma_px = scene.options.pixel_sigma;
  LandmarkInitialiser initialiser(scene.key, scene.camera, scene.options);
  int64_t next_id = int64_t{1} << 40;
  int added = 0;
  const LandmarkArchive no_archive;
  EXPECT_TRUE(initialiser
                  .initialise(run.state, run.book, no_archive,
                              scene.observe(scene.truth, 0, sigma_px, rng), 0, &next_id, &added)
                  .ok());
  EXPECT_EQ(added, static_cast<int>(scene.landmarks.size()));
  // The excursion: the mean stays, the covariance grows by Q, the truth is now x_est − e0 − d.
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(Q.rows(), Q.cols());
  EXPECT_TRUE(
      CovarianceHelper::propagate(run.state, scene.key, x_est, I, Q, UpdatePolicy::ekf()).ok());
  run.error_before = e0 + d;
  const StereoCamera::Vector9d seen_from = x_est - run.error_before;
  StereoUpdater updater(scene.key, scene.camera, scene.options);
  LoopCloser closer(scene.key, scene.camera, scene.options);
  FilterStatistics stats;
  EXPECT_TRUE(closer
                  .process(run.state, run.book,
                           scene.observe(seen_from, 40 * kUsPerS, sigma_px, rng), 40 * kUsPerS,
                           updater, UpdatePolicy::ekf(), &stats, &run.report)
                  .ok());
  return run;
}

Eigen::MatrixXd diagonal(double position_sigma, double attitude_sigma) {
  Eigen::VectorXd s(vehicle::kSizeNoBias);
  s << Eigen::Vector3d::Constant(position_sigma), Eigen::Vector3d::Constant(0.05),
      Eigen::Vector3d::Constant(attitude_sigma);
  return s.cwiseAbs2().asDiagonal();
}

/// Pose error (position, attitude) of the vehicle after the loop.
Eigen::Matrix<double, 6, 1> poseError(const LoopRun& run, const LoopScene& scene,
                                      const Eigen::VectorXd& truth) {
  const Eigen::VectorXd x = run.state.value(*run.state.find(scene.key));
  Eigen::Matrix<double, 6, 1> e;
  e << x.head<3>() - truth.head<3>(), x.segment<3>(6) - truth.segment<3>(6);
  return e;
}

/// The (position, attitude) block of a vehicle covariance (Euler layout).
Eigen::Matrix<double, 6, 6> poseCovariance(const Eigen::MatrixXd& P) {
  Eigen::Matrix<double, 6, 6> out;
  out << P.topLeftCorner<3, 3>(), P.block<3, 3>(0, 6), P.block<3, 3>(6, 0), P.block<3, 3>(6, 6);
  return out;
}

TEST(LoopCloserUpdate, ClosesADriftItsCovarianceExplainsThroughTheGain) {
  const LoopScene scene;
  std::mt19937 rng(11);
  const Eigen::MatrixXd P0 = diagonal(0.05, 0.002), Q = diagonal(1.5, 0.01);
  Eigen::VectorXd d = Eigen::VectorXd::Zero(vehicle::kSizeNoBias);
  d.head<3>() << 2.0, -1.5, 0.4;  // 1.4σ, 1σ, 0.3σ
  d(vehicle::kAttitude + 2) = 0.012;
  const LoopRun run = closeLoop(scene, P0, Q, Eigen::VectorXd::Zero(9), d, rng);
  ASSERT_TRUE(run.report.loop_closure);
  EXPECT_FALSE(run.report.loop_refused);
  EXPECT_EQ(run.report.nis_dof, 4 * static_cast<int>(scene.landmarks.size()));
  EXPECT_LT(run.report.nis, chiSquareQuantile(0.9999, run.report.nis_dof));
  const Eigen::VectorXd truth = scene.truth - d;  // where the vehicle is at the loop
  const Eigen::Matrix<double, 6, 1> e = poseError(run, scene, truth);
  EXPECT_LT(e.head<3>().norm(), 0.1 * d.head<3>().norm()) << e.transpose();  // 2.5 m before
  const StateVariable* v = run.state.find(scene.key);
  EXPECT_LT(e.dot(poseCovariance(run.state.covarianceOf(*v)).ldlt().solve(e)),
            chiSquareQuantile(0.999, 6));
  const double position_variance = run.state.covarianceOf(*v).topLeftCorner<3, 3>().trace();
  const double drift_variance = Q.topLeftCorner<3, 3>().trace();
  EXPECT_LT(position_variance, 0.1 * drift_variance);
  // The landmarks were mapped from the estimate before the drift: they do not move.
  const StateVariable* lm = run.state.find(VariableKey::landmark(100));
  EXPECT_LT((run.state.value(*lm) - scene.landmarks[0]).norm(), 0.6);
}

TEST(LoopCloserUpdate, RefusesADriftItsCovarianceCannotExplainAndLeavesTheState) {
  const LoopScene scene;
  std::mt19937 rng(12);
  const Eigen::MatrixXd P0 = diagonal(0.05, 0.002), Q = diagonal(0.3, 0.002);
  Eigen::VectorXd d = Eigen::VectorXd::Zero(vehicle::kSizeNoBias);
  d.head<3>() << 2.0, -1.5, 0.0;  // 8σ: inside the alignment's reach, outside the covariance
  const LoopRun run = closeLoop(scene, P0, Q, Eigen::VectorXd::Zero(9), d, rng);
  EXPECT_FALSE(run.report.loop_closure);
  EXPECT_TRUE(run.report.loop_refused);
  EXPECT_GT(run.report.nis, chiSquareQuantile(0.9999, run.report.nis_dof));
  const Eigen::VectorXd x = run.state.value(*run.state.find(scene.key));
  EXPECT_EQ(x, Eigen::VectorXd(scene.truth));  // the estimate did not move
}

TEST(LoopCloserUpdate, ClosedLoopsAreConsistentOverDrawsOfTheDrift) {
  // Monte Carlo over the initial error, the drift and the pixel noise, each drawn from the
  // covariance the filter states: the pose NEES after the loop must average its 6 dof (χ²
  // 95 % band of the mean of N runs), as it does only if the loop's correction and the
  // covariance it leaves agree.
  const LoopScene scene;
  const Eigen::MatrixXd P0 = diagonal(0.05, 0.002), Q = diagonal(1.0, 0.01);
  const Eigen::MatrixXd L0 = P0.llt().matrixL(), LQ = Q.llt().matrixL();
  std::mt19937 rng(2024);
  std::normal_distribution<double> n01(0.0, 1.0);
  constexpr int kRuns = 100;
  double nees_sum = 0.0;
  int closed = 0;
  for (int k = 0; k < kRuns; ++k) {
    Eigen::VectorXd w0(9), wd(9);
    for (int i = 0; i < 9; ++i) w0(i) = n01(rng), wd(i) = n01(rng);
    const Eigen::VectorXd e0 = L0 * w0, d = LQ * wd;
    const LoopRun run = closeLoop(scene, P0, Q, e0, d, rng);
    if (!run.report.loop_closure) continue;
    ++closed;
    const Eigen::VectorXd truth = scene.truth - d;  // the estimate was scene.truth + e0
    const Eigen::Matrix<double, 6, 1> e = poseError(run, scene, truth);
    const Eigen::Matrix<double, 6, 6> P =
        poseCovariance(run.state.covarianceOf(*run.state.find(scene.key)));
    nees_sum += e.dot(P.ldlt().solve(e));
  }
  ASSERT_GE(closed, kRuns * 95 / 100);  // the gate refuses a drawn drift rarely
  const double nees = nees_sum / closed;
  const double lo = chiSquareQuantile(0.025, 6 * closed) / closed;
  const double hi = chiSquareQuantile(0.975, 6 * closed) / closed;
  RecordProperty("loop_pose_nees", std::to_string(nees));
  std::cout << "pose NEES after the loop, mean of " << closed << " runs: " << nees << " (band "
            << lo << "–" << hi << ")\n";
  EXPECT_GT(nees, lo) << "under-confident";
  EXPECT_LT(nees, hi) << "over-confident: mean NEES " << nees << " for 6 dof";
}

}  // namespace
}  // namespace cvslam
