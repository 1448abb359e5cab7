// The vehicle-keyed SLAM models (slam/stereo_updater.h, landmark_initialiser.h, loop_closer.h,
// ci_updater.h, landmark_book.h; filter/vehicle_model.h) on synthetic stereo frames. The key
// test runs two vehicles in ONE state, with uncorrelated blocks, and checks that every model
// gives each vehicle exactly what it gives that vehicle alone, leaving the other untouched.

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <iostream>
#include <vector>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/ins/vehicle_state_layout.h"
#include "cvslam/slam/ci_updater.h"
#include "cvslam/slam/landmark_book.h"
#include "cvslam/slam/landmark_initialiser.h"
#include "cvslam/slam/loop_closer.h"
#include "cvslam/slam/stereo_updater.h"
#include "jacobian_check.h"

namespace cvslam {
namespace {

constexpr int64_t kUsPerS = 1000000;

/// One vehicle of the synthetic scene: 10 m above flat-ish ground, level, heading `yaw`,
/// looking down at six landmarks around the point below it.
struct SceneVehicle {
  VariableKey key;
  int size = vehicle::kSizeNoBias;
  StereoCamera::Vector9d truth = StereoCamera::Vector9d::Zero();  ///< Euler layout
  Eigen::VectorXd x0;  ///< initial estimate (offset from the truth)
  Eigen::MatrixXd P0;
  std::vector<Eigen::Vector3d> landmarks;
  int64_t first_id = 0;
};

SceneVehicle sceneVehicle(uint64_t agent, int size, const Eigen::Vector3d& position, double yaw,
                          int64_t first_id) {
  SceneVehicle v;
  v.key = VariableKey::vehicle(agent);
  v.size = size;
  v.truth.segment<3>(vehicle::kPosition) = position;
  v.truth.segment<3>(vehicle::kVelocity) = Eigen::Vector3d(2.0, 0.1, 0.0);
  v.truth.segment<3>(vehicle::kAttitude) = Eigen::Vector3d(0.02, -0.01, yaw);
  v.x0 = Eigen::VectorXd::Zero(size);
  v.x0.head<9>() = v.truth;
  v.x0.head<3>() += Eigen::Vector3d(0.12, -0.08, 0.05);
  v.x0(vehicle::kAttitude + 2) += 0.01;
  v.P0 = Eigen::MatrixXd::Identity(size, size) * 1e-4;
  v.P0.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * 0.04;
  v.P0(0, 1) = v.P0(1, 0) = 0.01;
  v.P0.block<3, 3>(vehicle::kAttitude, vehicle::kAttitude) *= 0.5;
  v.first_id = first_id;
  const double offsets[6][3] = {{0.8, 0.5, 0.0},    {-0.9, 0.4, -0.5}, {0.3, -1.1, 0.2},
                                {-0.4, -0.6, -1.0}, {1.2, -0.3, -0.3}, {-1.3, 1.0, 0.1}};
  for (const auto& o : offsets) {
    v.landmarks.push_back(Eigen::Vector3d(position.x() + o[0], position.y() + o[1], o[2]));
  }
  return v;
}

/// The vehicle's observations of its landmarks at t_us, with a deterministic pixel error of
/// about `error_px`, as seen from the true pose moved by `shift` (a drifted estimate).
StereoFrameObservations observe(const SceneVehicle& v, const StereoCamera& camera, int64_t t_us,
                                double error_px, const Eigen::Vector3d& shift = {0, 0, 0}) {
  StereoFrameObservations f;
  f.t_us = t_us;
  StereoCamera::Vector9d seen_from = v.truth;
  seen_from.head<3>() -= shift;
  for (std::size_t k = 0; k < v.landmarks.size(); ++k) {
    StereoObservation o;
    o.landmark_id = v.first_id + static_cast<int64_t>(k);
    o.index = static_cast<uint32_t>(o.landmark_id);
    o.z = camera.project(seen_from, v.landmarks[k]);
    for (int i = 0; i < 4; ++i) o.z(i) += error_px * std::sin(1.7 * static_cast<double>(k) + i);
    f.observations.push_back(o);
  }
  return f;
}

/// A vehicle's models and book.
struct VehicleModels {
  VehicleModels(const SceneVehicle& v, const StereoCamera& camera, const SlamOptions& o)
      : updater(v.key, camera, o),
        initialiser(v.key, camera, o),
        loop_closer(v.key, camera, o),
        ci(v.key) {
    book.setVehicleYawDirection(
        vehicle_model::yawDirection(EstimatedPose::fromEuler(v.x0.head<9>()), v.size));
  }
  LandmarkBook book;
  StereoUpdater updater;
  LandmarkInitialiser initialiser;
  LoopCloser loop_closer;
  CiUpdater ci;
  int64_t next_fresh_id = int64_t{1} << 40;
};

/// Mean and covariance of `keys` in `state`.
struct Block {
  Eigen::VectorXd x;
  Eigen::MatrixXd P;
};
Block blockOf(const SlamState& state, const std::vector<VariableKey>& keys) {
  Block b;
  Expected<Eigen::MatrixXd> P = CovarianceHelper::marginalCovariance(state, keys);
  EXPECT_TRUE(P.ok());
  if (P.ok()) b.P = *P;
  for (const VariableKey& k : keys) {
    const StateVariable* v = state.find(k);
    EXPECT_NE(v, nullptr);
    if (v == nullptr) continue;
    b.x.conservativeResize(b.x.size() + v->size);
    b.x.tail(v->size) = state.value(*v);
  }
  return b;
}

double maxDifference(const Block& a, const Block& b) {
  if (a.x.size() != b.x.size() || a.P.rows() != b.P.rows()) return INFINITY;
  return std::max((a.x - b.x).cwiseAbs().maxCoeff(), (a.P - b.P).cwiseAbs().maxCoeff());
}

/// Covariance between the variables `a` and `b` of `state` (zero when uncorrelated).
double maxCrossCovariance(const SlamState& state, const std::vector<VariableKey>& a,
                          const std::vector<VariableKey>& b) {
  double out = 0.0;
  for (const VariableKey& ka : a) {
    for (const VariableKey& kb : b) {
      const StateVariable* va = state.find(ka);
      const StateVariable* vb = state.find(kb);
      out = std::max(
          out,
          state.covariance().block(va->index, vb->index, va->size, vb->size).cwiseAbs().maxCoeff());
    }
  }
  return out;
}

class TwoVehiclesInOneState : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const SceneVehicle* v : {&v1_, &v2_}) {
      ASSERT_TRUE(CovarianceHelper::addVariable(joint_, v->key, v->x0, v->P0).ok());
    }
    ASSERT_TRUE(CovarianceHelper::addVariable(alone1_, v1_.key, v1_.x0, v1_.P0).ok());
    ASSERT_TRUE(CovarianceHelper::addVariable(alone2_, v2_.key, v2_.x0, v2_.P0).ok());
  }

  /// Runs `step` for vehicle i on the joint state and on its own state, then checks that the
  /// vehicle's map is the same in both and that the other vehicle's map did not change.
  template <typename Step>
  void runAndCompare(int i, Step step, const char* what) {
    SceneVehicle& v = i == 1 ? v1_ : v2_;
    SlamState& alone = i == 1 ? alone1_ : alone2_;
    VehicleModels& joint_models = i == 1 ? joint1_ : joint2_;
    VehicleModels& alone_models = i == 1 ? alone1m_ : alone2m_;
    const VehicleModels& other_models = i == 1 ? joint2_ : joint1_;
    const VariableKey other = i == 1 ? v2_.key : v1_.key;
    const std::vector<VariableKey> other_keys = other_models.book.variablesIn(joint_, other);
    const Block other_before = blockOf(joint_, other_keys);
    const Block mine_before = blockOf(alone, alone_models.book.variablesIn(alone, v.key));

    step(joint_, joint_models, v);
    step(alone, alone_models, v);

    const std::vector<VariableKey> keys = joint_models.book.variablesIn(joint_, v.key);
    ASSERT_EQ(keys, alone_models.book.variablesIn(alone, v.key)) << what;
    ASSERT_EQ(static_cast<int>(keys.size()), alone.landmarkCount() + 1) << what;
    EXPECT_GT(maxDifference(blockOf(alone, keys), mine_before), 0.0) << what << " did nothing";
    const double difference = maxDifference(blockOf(joint_, keys), blockOf(alone, keys));
    EXPECT_LT(difference, 1e-12) << what;
    std::cout << what << ", vehicle " << i << ": joint vs alone max |difference| " << difference
              << "\n";
    EXPECT_EQ(maxDifference(blockOf(joint_, other_keys), other_before), 0.0)
        << what << ": the other vehicle's map changed";
    EXPECT_EQ(maxCrossCovariance(joint_, keys, other_keys), 0.0) << what;
  }

  StereoCamera camera_;
  // No propagation between the frames here: the drift the loop closer meets has no process
  // noise to explain it, so its joint NIS gate (test_loop_closer.cpp) is off in this fixture.
  SlamOptions options_ = [] {
    SlamOptions o;
    o.loop_closure_gate_probability = 0.0;
    return o;
  }();
  // Vehicle 1 without, vehicle 2 with IMU bias states, 40 m apart, different headings.
  SceneVehicle v1_ = sceneVehicle(1, vehicle::kSizeNoBias, {0.0, 0.0, -10.0}, 0.3, 1000);
  SceneVehicle v2_ = sceneVehicle(2, vehicle::kSizeWithBias, {40.0, -5.0, -9.0}, -1.2, 2000);
  SlamState joint_, alone1_, alone2_;
  VehicleModels joint1_{v1_, camera_, options_}, joint2_{v2_, camera_, options_};
  VehicleModels alone1m_{v1_, camera_, options_}, alone2m_{v2_, camera_, options_};
};

TEST_F(TwoVehiclesInOneState, EveryModelGivesEachVehicleItsSingleVehicleResult) {
  const LandmarkArchive no_archive;
  const UpdatePolicy policy = *FilterOptions{}.policy();
  for (int i : {1, 2}) {
    runAndCompare(
        i,
        [&](SlamState& s, VehicleModels& m, const SceneVehicle& v) {
          int added = 0;
          ASSERT_TRUE(m.initialiser
                          .initialise(s, m.book, no_archive, observe(v, camera_, 0, 0.0), 0,
                                      &m.next_fresh_id, &added)
                          .ok());
          EXPECT_EQ(added, 6);
        },
        "landmark initialiser");
  }
  for (int i : {1, 2}) {
    runAndCompare(
        i,
        [&](SlamState& s, VehicleModels& m, const SceneVehicle& v) {
          std::vector<UpdateReport> passes;
          ASSERT_TRUE(m.updater
                          .update(s, m.book, observe(v, camera_, kUsPerS / 10, 0.4), 2,
                                  StereoUpdater::Selection::kAll, {}, policy, &passes)
                          .ok());
          ASSERT_EQ(passes.size(), 2u);
          EXPECT_EQ(passes.back().observations_accepted, 6);
        },
        "stereo updater");
  }
  for (int i : {1, 2}) {
    runAndCompare(
        i,
        [&](SlamState& s, VehicleModels& m, const SceneVehicle& v) {
          // Seen again 31 s later from a drifted estimate: a loop closure.
          FilterStatistics stats;
          LoopReport report;
          ASSERT_TRUE(m.loop_closer
                          .process(s, m.book,
                                   observe(v, camera_, 31 * kUsPerS, 0.2, {0.6, -0.4, 0.0}),
                                   31 * kUsPerS, m.updater, policy, &stats, &report)
                          .ok());
          EXPECT_EQ(report.loop_landmarks, 6);
          EXPECT_TRUE(report.loop_closure);
        },
        "loop closer");
  }
  for (int i : {1, 2}) {
    runAndCompare(
        i,
        [&](SlamState& s, VehicleModels& m, const SceneVehicle& v) {
          CiPeerEstimates peer;
          const auto n = static_cast<Eigen::Index>(3);
          peer.y.resize(3 * n);
          peer.R = Eigen::MatrixXd::Identity(3 * n, 3 * n) * 3.0 * 0.01;
          for (Eigen::Index k = 0; k < n; ++k) {
            peer.ids.push_back(v.first_id + k);
            peer.y.segment<3>(3 * k) = v.landmarks[static_cast<std::size_t>(k)];
          }
          peer.vehicle_trace = 0.01;
          const Expected<CiChoice> c = m.ci.choose(s, peer, CiWeighting{});
          ASSERT_TRUE(c.ok());
          EXPECT_GT(c->omega1, 0.05);
          EXPECT_LT(c->omega1, 1.0);
          ASSERT_TRUE(m.ci.apply(s, m.book, peer.ids, peer.y, peer.R, c->omega1).ok());
        },
        "CI updater");
  }
}

TEST(LandmarkBook, RecordsPendingLoopsAndTheVehicleMap) {
  LandmarkBook book;
  book.add(7, {3, 10, 20, {1, 2}, Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(-2, 1, 0), true});
  book.add(9, {4, 11, 21, {}, Eigen::Vector3d(4, 5, 6), Eigen::Vector3d::Zero(), false});
  ASSERT_NE(book.find(7), nullptr);
  EXPECT_EQ(book.find(7)->index, 3u);
  EXPECT_EQ(book.find(8), nullptr);

  book.markPendingLoop(7, 100);
  book.markPendingLoop(7, 150);  // keeps the first time
  book.markPendingLoop(9, 120);
  book.expirePendingLoops(205, 100);
  EXPECT_FALSE(book.isPendingLoop(7)) << "pending since 100, expired after 100 µs";
  EXPECT_TRUE(book.isPendingLoop(9));
  std::optional<LandmarkBookEntry> removed = book.remove(9);
  ASSERT_TRUE(removed.has_value());
  EXPECT_EQ(removed->first_estimate, Eigen::Vector3d(4, 5, 6));
  EXPECT_FALSE(book.isPendingLoop(9)) << "a removed landmark is no longer pending";
  EXPECT_FALSE(book.remove(9).has_value());

  // The vehicle's map in a state: the vehicle and the book's landmarks, in state order.
  SlamState s;
  ASSERT_TRUE(CovarianceHelper::addVariable(s, VariableKey::vehicle(1), Eigen::VectorXd::Zero(9),
                                            Eigen::MatrixXd::Identity(9, 9))
                  .ok());
  ASSERT_TRUE(CovarianceHelper::addVariable(s, VariableKey::landmark(5), Eigen::Vector3d(0, 0, 1),
                                            Eigen::Matrix3d::Identity())
                  .ok());
  ASSERT_TRUE(CovarianceHelper::addVariable(s, VariableKey::landmark(7), Eigen::Vector3d(9, 8, 7),
                                            Eigen::Matrix3d::Identity())
                  .ok());
  const std::vector<VariableKey> mine = book.variablesIn(s, VariableKey::vehicle(1));
  ASSERT_EQ(mine.size(), 2u);
  EXPECT_EQ(mine[0], VariableKey::vehicle(1));
  EXPECT_EQ(mine[1], VariableKey::landmark(7));
  EXPECT_EQ(book.variablesIn(s, VariableKey::vehicle(2)).size(), 1u);
  book.clear();
  EXPECT_EQ(book.find(7), nullptr);
  EXPECT_EQ(book.vehicleYawDirection().size(), 0);
}

TEST(CiUpdater, ChoosesTheWeightOfEachMethod) {
  // A vehicle with one correlated landmark; the peer reports the landmark with trace 0.3.
  SlamState s;
  Eigen::MatrixXd Pv = Eigen::MatrixXd::Identity(9, 9) * 0.2;
  ASSERT_TRUE(
      CovarianceHelper::addVariable(s, VariableKey::vehicle(3), Eigen::VectorXd::Zero(9), Pv).ok());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3, 9);
  J.leftCols<3>().setIdentity();
  ASSERT_TRUE(CovarianceHelper::augment(s, VariableKey::landmark(4), Eigen::Vector3d(1, 2, 3),
                                        VariableKey::vehicle(3), J, Eigen::MatrixXd::Identity(3, 4),
                                        Eigen::Matrix4d::Identity() * 0.1)
                  .ok());
  CiPeerEstimates peer;
  peer.ids = {4};
  peer.y = Eigen::Vector3d(1.1, 2.0, 2.9);
  peer.R = Eigen::Matrix3d::Identity() * 0.1;
  peer.vehicle_trace = 0.05;
  const CiUpdater ci(VariableKey::vehicle(3));
  const double own_landmark = 3 * (0.2 + 0.1), own_vehicle = 3 * 0.2;

  Expected<CiChoice> fast = ci.choose(s, peer, {CiMethod::kFast, 0.05});
  ASSERT_TRUE(fast.ok());
  EXPECT_NEAR(fast->omega1, 0.3 / (own_landmark + 0.3), 1e-12);  // eq. 6.4
  EXPECT_NEAR(fast->own_vehicle_trace, own_vehicle, 1e-12);
  Expected<CiChoice> adaptive = ci.choose(s, peer, {CiMethod::kAdaptive, 0.05});
  ASSERT_TRUE(adaptive.ok());
  EXPECT_NEAR(adaptive->omega1, (0.3 + 0.05) / (own_landmark + 0.3 + own_vehicle + 0.05),
              1e-12);  // eq. 6.5
  // ω1 ≈ 0.19 inflates the prior by 5.3: the fused vehicle position trace (≈ 1.21) exceeds the
  // prior's 0.6, so this fusion would not pay (require_vehicle_gain skips it).
  EXPECT_FALSE(adaptive->vehicle_gain);
  Expected<CiChoice> clamped = ci.choose(s, peer, {CiMethod::kFast, 0.5});
  ASSERT_TRUE(clamped.ok());
  EXPECT_EQ(clamped->omega1, 0.5);
  for (CiMethod m :
       {CiMethod::kOptimalTrace, CiMethod::kOptimalDeterminant, CiMethod::kOptimalVehicle}) {
    Expected<CiChoice> c = ci.choose(s, peer, {m, 0.05});
    ASSERT_TRUE(c.ok());
    EXPECT_GE(c->omega1, 0.05);
    EXPECT_LE(c->omega1, 1.0);
  }
  // optimal_vehicle minimises the fused vehicle position trace over ω1, below the prior's.
  Expected<CiChoice> best = ci.choose(s, peer, {CiMethod::kOptimalVehicle, 0.05});
  ASSERT_TRUE(best.ok());
  EXPECT_TRUE(best->vehicle_gain);
  const Eigen::MatrixXd P = s.covariance();
  for (double w : {0.1, 0.3, 0.5, 0.7, 0.9}) {
    EXPECT_LE(jointCiVehiclePositionTrace(P.topLeftCorner(3, 3), P.block(0, 9, 3, 3),
                                          P.block(9, 9, 3, 3), peer.R, best->omega1),
              jointCiVehiclePositionTrace(P.topLeftCorner(3, 3), P.block(0, 9, 3, 3),
                                          P.block(9, 9, 3, 3), peer.R, w) +
                  1e-9);
  }
  // A peer landmark the state does not hold is an error, not a silent no-op.
  peer.ids = {5};
  EXPECT_FALSE(ci.choose(s, peer, {CiMethod::kFast, 0.05}).ok());
}

TEST(CiUpdater, TheIntersectionBoundsHeldLandmarksToo) {
  // A vehicle, an active landmark 4 and a held (Schmidt) landmark 5, both correlated with the
  // vehicle. The peer's estimate of landmark 4 shares the error of landmark 5 (it was built from
  // this agent's map): e_y = e_5 + n. CI must bound the fused joint error of [4; 5] whatever that
  // correlation, which it does only when the held landmark's prior is scaled by 1/ω1 too.
  const Eigen::Vector3d p(1, 2, 3);  // both landmarks' estimate
  SlamState s;
  ASSERT_TRUE(CovarianceHelper::addVariable(s, VariableKey::vehicle(3), Eigen::VectorXd::Zero(9),
                                            Eigen::MatrixXd::Identity(9, 9) * 0.2)
                  .ok());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3, 9);
  J.leftCols<3>().setIdentity();
  for (uint64_t id : {4u, 5u})
    ASSERT_TRUE(CovarianceHelper::augment(s, VariableKey::landmark(id), p, VariableKey::vehicle(3),
                                          J, Eigen::MatrixXd::Identity(3, 4),
                                          Eigen::Matrix4d::Identity() * 0.02)
                    .ok());
  ASSERT_TRUE(
      CovarianceHelper::rekey(s, VariableKey::landmark(5), VariableKey::heldLandmark(5)).ok());
  LandmarkBook book;
  book.add(4, {4, 0, 0, {}, p, Eigen::Vector3d::Zero(), false});
  const Eigen::MatrixXd P = s.covariance();  // [vehicle 9; landmark 4; held 5]
  const Eigen::Index l4 = 9, h5 = 12;
  const Eigen::Matrix3d N = Eigen::Matrix3d::Identity() * 0.01;
  const Eigen::Matrix3d R = P.block<3, 3>(h5, h5) + N;  // the peer's true (and reported) covariance
  const double omega1 = 0.5;
  const CiUpdater ci(VariableKey::vehicle(3));
  // The gain of the landmarks' rows, column by column (the update is linear in the residual).
  const auto fused = [&](const Eigen::Vector3d& residual, SlamState* out) {
    *out = s;
    LandmarkBook b = book;
    ASSERT_TRUE(ci.apply(*out, b, {4}, p + residual, R, omega1).ok());
  };
  SlamState after;
  Eigen::Matrix<double, 6, 3> K;
  for (int c = 0; c < 3; ++c) {
    fused(Eigen::Vector3d::Unit(c), &after);
    K.block<3, 1>(0, c) = after.mean().segment<3>(l4) - p;
    K.block<3, 1>(3, c) = after.mean().segment<3>(h5) - p;
  }
  EXPECT_NEAR(K.bottomRows<3>().norm(), 0.0, 1e-12) << "a held landmark has no gain";
  // True error of [4; 5] after the update: e⁺ = e + K (e_y − e_4), Cov(e, e_y) = P(:, 5).
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Identity();
  A.block<6, 3>(0, 0) -= K;  // e⁺ = A e + K e_y
  Eigen::Matrix<double, 6, 6> P45;
  P45 << P.block<3, 3>(l4, l4), P.block<3, 3>(l4, h5), P.block<3, 3>(h5, l4), P.block<3, 3>(h5, h5);
  Eigen::Matrix<double, 6, 3> C;  // Cov([e_4; e_5], e_y)
  C << P.block<3, 3>(l4, h5), P.block<3, 3>(h5, h5);
  const Eigen::Matrix<double, 6, 6> truth = A * P45 * A.transpose() + K * R * K.transpose() +
                                            A * C * K.transpose() +
                                            K * C.transpose() * A.transpose();
  fused(Eigen::Vector3d::Zero(), &after);
  const Eigen::MatrixXd Pa = after.covariance();
  Eigen::Matrix<double, 6, 6> claimed;
  claimed << Pa.block<3, 3>(l4, l4), Pa.block<3, 3>(l4, h5), Pa.block<3, 3>(h5, l4),
      Pa.block<3, 3>(h5, h5);
  const Eigen::Matrix<double, 6, 6> excess = claimed - truth;
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(excess).eigenvalues().minCoeff(), -1e-12)
      << "the fused covariance of [landmark 4; held 5] does not bound its error";
  EXPECT_TRUE((Pa.block<3, 3>(h5, h5).isApprox(P.block<3, 3>(h5, h5) / omega1, 1e-12)))
      << "the held landmark carries the CI discount 1/ω1";
}

TEST(VehicleModel, PoseJacobianAndCorrectionOfTheVehicleBlock) {
  // The stereo Jacobian w.r.t. the whole vehicle block (bias columns zero) placed by the
  // vehicle model matches finite differences of h(pose(x_v)).
  const StereoCamera camera;
  Eigen::VectorXd x_v = Eigen::VectorXd::Zero(vehicle::kSizeWithBias);
  x_v.head<9>() << 1.0, -2.0, -10.0, 2.0, 0.1, 0.0, 0.03, -0.02, 0.7;
  const Eigen::Vector3d p_L(1.5, -1.2, 0.3);
  SlamState s;
  ASSERT_TRUE(CovarianceHelper::addVariable(s, VariableKey::vehicle(4), x_v,
                                            Eigen::MatrixXd::Identity(15, 15))
                  .ok());
  const StateVariable& veh = *s.find(VariableKey::vehicle(4));
  StereoCamera::Matrix4x9d dz_dpose;
  camera.project(vehicle_model::pose(s, veh), p_L, &dz_dpose);
  MeasurementBatch batch;
  batch.reset(s.size(), 4);
  const int g = batch.addObservation(Eigen::Vector4d::Zero(), Eigen::Matrix4d::Identity());
  vehicle_model::setPoseJacobian(batch, g, veh, dz_dpose);
  const auto h = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
    SlamState t = s;
    t.setValue(*t.find(VariableKey::vehicle(4)), x);
    return camera.project(vehicle_model::pose(t, *t.find(VariableKey::vehicle(4))), p_L);
  };
  EXPECT_TRUE(test::jacobianMatches(h, x_v, batch.H()));

  // Triangulation Jacobian w.r.t. the block, likewise.
  const Eigen::Vector4d z = camera.project(x_v.head<9>(), p_L);
  StereoCamera::Matrix3x9d dpL_dpose;
  Eigen::Vector3d p;
  ASSERT_TRUE(camera.triangulate(z, x_v.head<9>(), &p, &dpL_dpose).ok());
  Eigen::MatrixXd dpL_dblock = Eigen::MatrixXd::Zero(3, 15);
  vehicle_model::poseToBlockJacobian(dpL_dpose, &dpL_dblock);
  const auto g_inv = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
    Eigen::Vector3d out;
    EXPECT_TRUE(camera.triangulate(z, x.head<9>(), &out).ok());
    return out;
  };
  EXPECT_TRUE(test::jacobianMatches(g_inv, x_v, dpL_dblock));

  // The correction keeps the angles wrapped; the rigid move turns the heading only.
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(15);
  dx(vehicle::kAttitude + 2) = 3.0;
  dx(vehicle::kAccelBias) = 0.01;
  Eigen::VectorXd corrected = x_v;
  vehicle_model::correct(corrected, dx, nullptr);
  EXPECT_NEAR(corrected(vehicle::kAttitude + 2), wrapAngle(0.7 + 3.0), 1e-15);
  EXPECT_LE(corrected(vehicle::kAttitude + 2), M_PI);
  EXPECT_EQ(corrected(vehicle::kAccelBias), 0.01);
  vehicle_model::moveRigidly(s, veh, Eigen::Vector3d(5, 6, -9), 0.2);
  const Eigen::VectorXd moved = s.value(*s.find(VariableKey::vehicle(4)));
  EXPECT_EQ(moved.head<3>(), Eigen::Vector3d(5, 6, -9));
  EXPECT_NEAR(moved(vehicle::kAttitude + 2), 0.9, 1e-15);
  EXPECT_EQ(moved.segment<5>(vehicle::kVelocity), x_v.segment<5>(vehicle::kVelocity));
  // u_v: a global yaw moves the position by e3 × p and ψ by 1.
  const Eigen::VectorXd u = vehicle_model::yawDirection(
      EstimatedPose::fromEuler(
          (StereoCamera::Vector9d() << 1, -2, -10, 0, 0, 0, 0, 0, 0).finished()),
      15);
  EXPECT_EQ(u.head<3>(), Eigen::Vector3d(2, 1, 0));
  EXPECT_EQ(u(vehicle::kAttitude + 2), 1.0);
  EXPECT_EQ(u.tail<6>(), Eigen::VectorXd::Zero(6));
}

/// Error state: ∂h/∂δθ of the stereo observation and ∂landmark/∂pose of the inverse model
/// against central differences of R̂ Exp(δθ), at a level attitude and at pitch 90° (IMU x
/// axis up); the correction folds δθ into R̂; the rigid move turns R̂ about N's z; the Euler
/// layout round-trips.
TEST(VehicleModel, ErrorStatePoseJacobiansCorrectionAndEulerLayout) {
  const StereoCamera camera;
  const VariableKey key = VariableKey::vehicle(2);
  Eigen::VectorXd x_v = Eigen::VectorXd::Zero(vehicle::kSizeWithBias);
  x_v.head<6>() << 1.0, -2.0, -10.0, 2.0, 0.1, 0.0;
  const Eigen::Quaterniond level(rotationBodyToNav(Eigen::Vector3d(0.03, -0.02, 0.7)));
  // Pitch 90°, camera still looking at the point: the nose points up, the camera forward.
  const Eigen::Quaterniond up(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()));
  for (const Eigen::Quaterniond& q : {level, up}) {
    SlamState s;
    ASSERT_TRUE(vehicle_model::addVehicle(s, key, x_v, q, Eigen::MatrixXd::Identity(15, 15)).ok());
    const StateVariable& veh = *s.find(key);
    const vehicle_model::Pose pose = vehicle_model::pose(s, veh);
    EXPECT_EQ(pose.attitude, vehicle::Attitude::kErrorState);
    // A landmark in front of the camera whatever the attitude.
    const Eigen::Vector3d p_C(0.3, -0.2, 4.0);
    const StereoCameraOptions& c = camera.options();
    const Eigen::Vector3d p_LinN =
        pose.p_BinN + pose.R_BtoN * (c.R_BtoC.transpose() * p_C + c.p_CinB);
    StereoCamera::Matrix4x9d dz_dpose;
    camera.project(pose, p_LinN, &dz_dpose);
    const auto moved = [&](const Eigen::VectorXd& x) {
      SlamState t = s;
      t.setValue(*t.find(key), x);
      return vehicle_model::pose(t, *t.find(key));
    };
    const auto h = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
      return camera.project(moved(x), p_LinN);
    };
    Eigen::MatrixXd dz_dblock = Eigen::MatrixXd::Zero(4, 15);
    dz_dblock.leftCols<9>() = dz_dpose;
    EXPECT_TRUE(test::jacobianMatches(h, x_v, dz_dblock));
    const Eigen::Vector4d z = camera.project(pose, p_LinN);
    StereoCamera::Matrix3x9d dpL_dpose;
    Eigen::Vector3d p;
    ASSERT_TRUE(camera.triangulate(z, pose, &p, &dpL_dpose).ok());
    EXPECT_LT((p - p_LinN).norm(), 1e-9);
    Eigen::MatrixXd dpL_dblock = Eigen::MatrixXd::Zero(3, 15);
    vehicle_model::poseToBlockJacobian(dpL_dpose, &dpL_dblock);
    const auto g_inv = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
      Eigen::Vector3d out;
      EXPECT_TRUE(camera.triangulate(z, moved(x), &out).ok());
      return out;
    };
    EXPECT_TRUE(test::jacobianMatches(g_inv, x_v, dpL_dblock));
  }

  // Correction: δθ folded into R̂, the entries zeroed, the rest added.
  Eigen::VectorXd corrected = x_v;
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(15);
  dx.segment<3>(vehicle::kAttitude) << 0.01, 0.02, -0.03;
  dx(vehicle::kAccelBias) = 0.01;
  Eigen::Quaterniond nominal = level;
  vehicle_model::correct(corrected, dx, &nominal);
  EXPECT_EQ(corrected.segment<3>(vehicle::kAttitude), Eigen::Vector3d::Zero());
  EXPECT_EQ(corrected(vehicle::kAccelBias), 0.01);
  const Eigen::Matrix3d expected =
      level.toRotationMatrix() *
      so3::exp<double>(Eigen::Vector3d(dx.segment<3>(vehicle::kAttitude)));
  EXPECT_LT((nominal.toRotationMatrix() - expected).norm(), 1e-12);

  // Rigid move and the Euler layout (round trip of mean and covariance).
  SlamState s;
  Eigen::MatrixXd P = Eigen::MatrixXd::Identity(15, 15) * 0.01;
  P(vehicle::kAttitude, vehicle::kAttitude + 2) = P(vehicle::kAttitude + 2, vehicle::kAttitude) =
      0.002;
  Eigen::VectorXd x_euler = x_v;
  x_euler.segment<3>(vehicle::kAttitude) << 0.03, -0.02, 0.7;
  ASSERT_TRUE(vehicle_model::addVehicle(s, key, x_euler, P, vehicle::Attitude::kErrorState).ok());
  Eigen::VectorXd x_out;
  Eigen::MatrixXd P_out;
  vehicle_model::eulerLayout(s, *s.find(key), &x_out, &P_out);
  EXPECT_LT((x_out - x_euler).norm(), 1e-12);
  EXPECT_LT((P_out - P).norm(), 1e-12);
  vehicle_model::moveRigidly(s, *s.find(key), Eigen::Vector3d(5, 6, -9), 0.2);
  vehicle_model::eulerLayout(s, *s.find(key), &x_out, &P_out);
  EXPECT_EQ(x_out.head<3>(), Eigen::Vector3d(5, 6, -9));
  EXPECT_NEAR(x_out(vehicle::kAttitude + 2), 0.9, 1e-12);
  EXPECT_NEAR(x_out(vehicle::kAttitude), 0.03, 1e-12);
  EXPECT_EQ(s.value(*s.find(key)).segment<3>(vehicle::kAttitude), Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace cvslam
