#pragma once
// Random but reproducible joint states and stacked measurements for the filter tests and the
// filter benchmark (no gtest here: the benchmarks include it too).

#include <Eigen/Core>
#include <random>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam::test {

inline Eigen::MatrixXd randomMatrix(int rows, int cols, std::mt19937& rng, double scale = 1.0) {
  std::normal_distribution<double> n(0.0, scale);
  Eigen::MatrixXd M(rows, cols);
  for (int c = 0; c < cols; ++c)
    for (int r = 0; r < rows; ++r) M(r, c) = n(rng);
  return M;
}

/// A well-conditioned random covariance with standard deviations around `sigma`.
inline Eigen::MatrixXd randomCovariance(int n, std::mt19937& rng, double sigma = 0.1) {
  const Eigen::MatrixXd A = randomMatrix(n, n, rng, sigma);
  return A * A.transpose() / n + 0.2 * sigma * sigma * Eigen::MatrixXd::Identity(n, n);
}

/// Vehicle (key vehicle(0), `vehicle_size` states) plus `landmarks` landmarks (ids 100, 101,
/// ...) initialised through augmentation from the vehicle, so every block is correlated.
inline SlamState randomSlamState(int landmarks, std::mt19937& rng,
                                 int vehicle_size = vehicle::kSizeNoBias) {
  SlamState state;
  Eigen::VectorXd xv = randomMatrix(vehicle_size, 1, rng, 0.3);
  CovarianceHelper::addVariable(state, VariableKey::vehicle(0), xv,
                                randomCovariance(vehicle_size, rng, 0.1));
  for (int j = 0; j < landmarks; ++j) {
    CovarianceHelper::augment(state, VariableKey::landmark(100 + static_cast<uint64_t>(j)),
                              randomMatrix(3, 1, rng, 5.0), VariableKey::vehicle(0),
                              randomMatrix(3, vehicle_size, rng, 0.5),
                              randomMatrix(3, 4, rng, 0.05), Eigen::Matrix4d::Identity());
  }
  return state;
}

/// `observations` stereo-like observations (4 rows: 4×vehicle + 4×3 landmark blocks) of
/// landmarks chosen in turn, with pixel noise σ = `sigma_px` and random residuals of that size.
inline void randomStereoBatch(const SlamState& state, int observations, std::mt19937& rng,
                              MeasurementBatch* batch, double sigma_px = 1.0) {
  batch->reset(state.size(), 4 * observations);
  const StateVariable* vehicle = state.find(VariableKey::vehicle(0));
  std::vector<const StateVariable*> landmarks;
  for (const StateVariable& v : state.variables())
    if (v.key.kind == VariableKey::Kind::kLandmark) landmarks.push_back(&v);
  const Eigen::Matrix4d R = sigma_px * sigma_px * Eigen::Matrix4d::Identity();
  for (int k = 0; k < observations; ++k) {
    const int g = batch->addObservation(randomMatrix(4, 1, rng, sigma_px), R);
    batch->setJacobian(g, *vehicle, randomMatrix(4, vehicle->size, rng, 20.0));
    batch->setJacobian(g, *landmarks[static_cast<std::size_t>(k) % landmarks.size()],
                       randomMatrix(4, 3, rng, 20.0));
  }
}

}  // namespace cvslam::test
