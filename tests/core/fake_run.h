#pragma once
// A synthetic run folder written through the real writers (AgentRunWriter), for the
// evaluation and plotting tests: the vehicle flies a circle, the estimate is the truth plus
// noise drawn from the recorded covariance (so NEES ≈ 9 by construction).

#include <Eigen/Cholesky>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include "cvslam/io/run_writer.h"

namespace cvslam::test {

struct FakeRunOptions {
  int agents = 2;
  int steps = 400;
  double dt = 0.1;
  double radius_m = 20.0;
  double speed_mps = 5.0;
  unsigned seed = 1;
  bool write_ins = true;
  double t0 = 100.0;  ///< time of the first step [s] (a EuRoC-epoch time for real-data tests)
};

/// The covariance every estimate is drawn from: correlated, SPD, state-dependent units.
inline Matrix9d fakeCovariance() {
  Vector9d sigma;
  sigma << 0.3, 0.4, 0.2, 0.05, 0.05, 0.03, 0.01, 0.01, 0.02;
  Matrix9d C = Matrix9d::Identity();
  C(0, 1) = C(1, 0) = 0.5;
  C(6, 2) = C(2, 6) = -0.3;
  C(3, 8) = C(8, 3) = 0.2;
  return sigma.asDiagonal() * C * sigma.asDiagonal();
}

inline Vector9d circleState(double t, const FakeRunOptions& o, int agent) {
  const double w = o.speed_mps / o.radius_m;
  const double a = w * t + agent;  // agents start at different places on the circle
  Vector9d x;
  x << o.radius_m * std::cos(a), o.radius_m * std::sin(a), -10.0 - agent, o.speed_mps, 0, 0, 0, 0,
      std::remainder(a + M_PI / 2, 2 * M_PI);
  return x;
}

inline void writeFakeRun(const std::string& dir, const FakeRunOptions& o = {}) {
  std::filesystem::remove_all(dir);
  RunInfo info;
  info.mode = "dc";
  info.filter = "nhinf";
  info.map = "knearest";
  writeRunInfo(dir, info);
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> n01;
  const Matrix9d P = fakeCovariance();
  const Matrix9d L = P.llt().matrixL();
  for (int agent = 1; agent <= o.agents; ++agent) {
    AgentRunWriter w;
    w.open(dir, agent);
    for (int k = 0; k < o.steps; ++k) {
      const double t = o.t0 + k * o.dt;
      const Vector9d x = circleState(k * o.dt, o, agent);
      Vector9d noise;
      for (int i = 0; i < 9; ++i) noise(i) = n01(rng);
      w.addState(t, x + L * noise, P);
      w.addTruth(t, x);
      if (o.write_ins) {
        Vector9d x_ins = x;
        x_ins(0) += 0.01 * k;  // dead reckoning drifts
        w.addInsState(t, x_ins);
      }
      FrameStats f;
      f.t = t;
      f.time_ms = 10.0 + (k % 5);
      f.state_size = 9 + 3 * std::min(k, 20);
      f.landmarks = std::min(k, 20);
      f.landmark_sigma_mean_m = 1.0 / (1.0 + 0.1 * k);
      w.addFrame(f);
      w.addBytesSent(1000);
    }
    std::vector<LandmarkRecord> map;
    for (int i = 0; i < 30; ++i) {
      LandmarkRecord l;
      l.id = 1000 * agent + i;
      l.truth = Eigen::Vector3d(i, -i, 0.5 * i);
      l.p_LinN =
          *l.truth + Eigen::Vector3d(0.1, -0.2, 0.3) + 0.05 * Eigen::Vector3d(n01(rng), 0, 0);
      l.var = Eigen::Vector3d::Constant(0.01);
      map.push_back(l);
    }
    w.writeLandmarks(map);
    w.close();
  }
}

}  // namespace cvslam::test
