// The right-invariant error chart (slam_state.h ErrorChart, CovarianceHelper::correctMean):
// an update that moves the mean must carry the unobservable yaw direction from the prior mean
// to the posterior one, so that observations which cannot see a global yaw add no information
// about it — the property the additive chart loses (Huang, Mourikis & Roumeliotis 2010).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/geometry/so3.h"

namespace cvslam {
namespace {

const VariableKey kVehicle = VariableKey::vehicle(1);
constexpr int kLandmarks = 3;
constexpr int kUpdates = 3;

/// Vehicle (15 states, yaw σ 0.5 rad) and three landmarks triangulated from it (so their
/// covariance shares the vehicle's yaw uncertainty along the global yaw direction).
SlamState makeState(vehicle::Attitude attitude, ErrorChart chart) {
  SlamState state;
  state.setErrorChart(chart);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(vehicle::kSizeWithBias);
  x.head<9>() << 12.0, -7.0, -10.0, 3.0, 0.2, 0.1, 0.05, -0.03, 0.8;
  Eigen::MatrixXd P = 0.05 * Eigen::MatrixXd::Identity(x.size(), x.size());
  P(vehicle::kAttitude + 2, vehicle::kAttitude + 2) = 0.25;
  EXPECT_TRUE(vehicle_model::addVehicle(state, kVehicle, x, P, attitude).ok());
  const Eigen::Vector3d offsets[kLandmarks] = {
      {8.0, 4.0, 9.0}, {5.0, -6.0, 11.0}, {14.0, 1.0, 8.0}};  // body frame
  for (int j = 0; j < kLandmarks; ++j) {
    const StateVariable& v = *state.find(kVehicle);
    const vehicle_model::Pose pose = vehicle_model::pose(state, v);
    const Eigen::Vector3d l = pose.p_BinN + pose.R_BtoN * offsets[j];
    // ∂l/∂x_v: identity on the position, ∂(R b)/∂a = −[R b]× M on the attitude.
    Eigen::MatrixXd dl_dv = Eigen::MatrixXd::Zero(3, v.size);
    dl_dv.block<3, 3>(0, vehicle::kPosition).setIdentity();
    dl_dv.block<3, 3>(0, vehicle::kAttitude) =
        -so3::skew<double>(Eigen::Vector3d(pose.R_BtoN * offsets[j])) *
        vehicle_model::navRotationPerAttitude(pose);
    EXPECT_TRUE(CovarianceHelper::augment(state, VariableKey::landmark(100 + j), l, kVehicle, dl_dv,
                                          Eigen::Matrix3d::Identity(),
                                          0.05 * Eigen::Matrix3d::Identity())
                    .ok());
  }
  return state;
}

/// The global yaw direction of the whole state at its mean.
Eigen::VectorXd yawDirection(const SlamState& state) {
  Eigen::VectorXd N = Eigen::VectorXd::Zero(state.size());
  for (const StateVariable& v : state.variables()) {
    if (v.key.kind == VariableKey::Kind::kVehicle) {
      N.segment(v.index, v.size) =
          vehicle_model::yawDirection(vehicle_model::pose(state, v), v.size);
    } else {
      N.segment<3>(v.index) = Eigen::Vector3d::UnitZ().cross(state.value(v).head<3>());
    }
  }
  return N;
}

double informationAlong(const SlamState& state, const Eigen::VectorXd& N) {
  return N.dot(state.covariance().ldlt().solve(N));
}

/// Each landmark in the body frame, Rᵀ(l − p): invariant under a global yaw. H by central
/// differences on the stored entries (the error state's δθ is part of the pose).
Eigen::VectorXd predict(const SlamState& state) {
  const StateVariable& v = *state.find(kVehicle);
  const vehicle_model::Pose pose = vehicle_model::pose(state, v);
  Eigen::VectorXd h(3 * kLandmarks);
  for (int j = 0; j < kLandmarks; ++j) {
    const StateVariable& l = *state.find(VariableKey::landmark(100 + j));
    h.segment<3>(3 * j) = pose.R_BtoN.transpose() * (state.value(l) - pose.p_BinN);
  }
  return h;
}

MeasurementBatch relativeObservations(const SlamState& state) {
  const int n = state.size();
  Eigen::MatrixXd H(3 * kLandmarks, n);
  constexpr double kStep = 1e-6;
  for (int i = 0; i < n; ++i) {
    SlamState plus = state, minus = state;
    for (const StateVariable& v : state.variables()) {
      if (i < v.index || i >= v.index + v.size) continue;
      Eigen::VectorXd x = state.value(v);
      x(i - v.index) += kStep;
      plus.setValue(v, x);
      x(i - v.index) -= 2.0 * kStep;
      minus.setValue(v, x);
    }
    H.col(i) = (predict(plus) - predict(minus)) / (2.0 * kStep);
  }
  MeasurementBatch batch;
  batch.reset(n, 3 * kLandmarks);
  const Eigen::Vector3d residual(0.4, -0.3, 0.25);  // moves the mean by decimetres
  for (int j = 0; j < kLandmarks; ++j) {
    const int g = batch.addObservation(residual, 1e-4 * Eigen::Matrix3d::Identity());
    batch.setJacobian(g, 0, H.middleRows<3>(3 * j));
  }
  return batch;
}

TEST(InvariantErrorChart, UpdatesAddNoInformationAboutTheGlobalYaw) {
  for (vehicle::Attitude attitude : {vehicle::Attitude::kEuler, vehicle::Attitude::kErrorState}) {
    SCOPED_TRACE(attitude == vehicle::Attitude::kEuler ? "Euler" : "error state");
    double gained[2] = {0.0, 0.0};
    Eigen::VectorXd first_posterior_mean[2];
    for (ErrorChart chart : {ErrorChart::kAdditive, ErrorChart::kRightInvariant}) {
      SlamState state = makeState(attitude, chart);
      const double before = informationAlong(state, yawDirection(state));
      for (int k = 0; k < kUpdates; ++k) {  // each linearised at the mean the last one left
        const MeasurementBatch batch = relativeObservations(state);
        EXPECT_LT((batch.H() * yawDirection(state)).norm(), 1e-6);  // h cannot see the yaw
        ASSERT_TRUE(CovarianceHelper::update(state, batch, UpdatePolicy::ekf(), nullptr).ok());
        if (k == 0) first_posterior_mean[chart == ErrorChart::kAdditive ? 0 : 1] = state.mean();
      }
      const int c = chart == ErrorChart::kAdditive ? 0 : 1;
      gained[c] = informationAlong(state, yawDirection(state)) / before;
    }
    std::cout << "yaw information after / before: additive " << gained[0] << ", invariant "
              << gained[1] << "\n";
    EXPECT_NEAR(gained[1], 1.0, 1e-4);  // carried exactly to the new mean
    EXPECT_GT(gained[0], 3.0);          // the additive chart fabricates it
    // The chart changes the covariance after an update, never that update's mean.
    EXPECT_LT((first_posterior_mean[0] - first_posterior_mean[1]).cwiseAbs().maxCoeff(), 1e-12);
  }
}

}  // namespace
}  // namespace cvslam
