// World and stereo observation simulation (cvslam/scenario/world.h, observation_simulator.h;
// thesis §5.4 eq. 5.20, §5.9 noise kinds): visibility, noise statistics per kind, outliers,
// feature cap, determinism.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "cvslam/scenario/position_path.h"
#include "cvslam/scenario/world.h"
#include "cvslam/sim/observation_simulator.h"
#include "sim_test_helpers.h"

namespace cvslam::sim {
namespace {

World makeWorld(double density = 1.0, uint64_t seed = 3) {
  WorldOptions o;
  o.landmark_density = density;
  o.relief_amplitude = 2.0;
  auto w = World::generate(
      o, Eigen::AlignedBox2d(Eigen::Vector2d(-60, -60), Eigen::Vector2d(60, 60)), seed);
  EXPECT_TRUE(w.ok());
  return std::move(*w);
}

std::shared_ptr<const Trajectory> circle() {
  LoopPath::Params p;
  p.semi_axis_x = p.semi_axis_y = 30;
  p.period = 60;
  return simtest::makeFlight(std::make_shared<LoopPath>(p));
}

TEST(SimWorld, LandmarksHaveUniqueIdsAndSitOnTerrain) {
  const World w = makeWorld(0.5);
  ASSERT_EQ(w.landmarks().size(), static_cast<std::size_t>(std::lround(0.5 * 120 * 120)));
  for (std::size_t i = 0; i < w.landmarks().size(); ++i) {
    const Landmark& l = w.landmarks()[i];
    ASSERT_EQ(l.id, i);
    const double ground = w.terrain().groundZ(l.p_LinN.x(), l.p_LinN.y());
    EXPECT_LE(l.p_LinN.z(), ground + 1e-12);        // above the ground (NED: smaller z)
    EXPECT_GE(l.p_LinN.z(), ground - 0.5 - 1e-12);  // by at most the jitter
  }
  // Same seed, same world; another seed, another world.
  EXPECT_EQ(makeWorld(0.5, 3).landmarks()[17].p_LinN, w.landmarks()[17].p_LinN);
  EXPECT_NE(makeWorld(0.5, 4).landmarks()[17].p_LinN, w.landmarks()[17].p_LinN);
}

TEST(SimObservation, EveryObservedLandmarkIsVisibleAndNoneIsMissed) {
  const World w = makeWorld();
  auto traj = circle();
  PixelNoiseOptions o;
  o.sigma_px = 0.0;
  ObservationSimulator sim(StereoCameraOptions{}, o, 9);
  const StereoCamera& cam = sim.camera();
  std::size_t total = 0;
  for (double t = 0; t < 60; t += 1.7) {
    const TrajectoryState s = traj->state(t);
    const auto frame = sim.observe(static_cast<int64_t>(t * 1e6), s, w);
    std::size_t brute = 0;
    for (const Landmark& l : w.landmarks()) {
      if (cam.isVisible(cam.landmarkInCamera(s.p_BinN, s.euler, l.p_LinN))) ++brute;
    }
    EXPECT_EQ(frame.observations.size(), brute) << "t=" << t;  // the grid search misses none
    uint32_t prev = 0;
    for (std::size_t i = 0; i < frame.observations.size(); ++i) {
      const StereoObservation& obs = frame.observations[i];
      if (i > 0) {
        EXPECT_GT(obs.index, prev);  // sorted, unique
      }
      prev = obs.index;
      const Eigen::Vector3d p_LinC =
          cam.landmarkInCamera(s.p_BinN, s.euler, w.landmarks()[obs.index].p_LinN);
      EXPECT_GT(p_LinC.z(), cam.options().min_depth);
      EXPECT_TRUE(cam.isVisible(p_LinC));
      EXPECT_LT((obs.z - cam.project(p_LinC)).norm(), 1e-9);
      for (int k : {0, 2}) EXPECT_TRUE(obs.z(k) >= 0 && obs.z(k) < cam.options().width);
      for (int k : {1, 3}) EXPECT_TRUE(obs.z(k) >= 0 && obs.z(k) < cam.options().height);
    }
    total += frame.observations.size();
  }
  EXPECT_GT(total, 200u);  // ≈24 m² in view at 10 m, 1 landmark per m²
}

// Pixel errors of many observations with the given noise options.
std::vector<Eigen::Vector4d> pixelErrors(const PixelNoiseOptions& o, uint64_t seed) {
  const World w = makeWorld();
  auto traj = circle();
  ObservationSimulator sim(StereoCameraOptions{}, o, seed);
  std::vector<Eigen::Vector4d> errors;
  for (double t = 0; t < 60; t += 0.1) {
    const TrajectoryState s = traj->state(t);
    for (const auto& obs : sim.observe(0, s, w).observations) {
      const Eigen::Vector3d p_LinC =
          sim.camera().landmarkInCamera(s.p_BinN, s.euler, w.landmarks()[obs.index].p_LinN);
      errors.push_back(obs.z - sim.camera().project(p_LinC));
    }
  }
  return errors;
}

TEST(SimObservation, NoiseStatisticsPerKind) {
  for (const auto& [name, kind] : noiseKindNames()) {
    for (NonGaussianShape shape : {NonGaussianShape::kUniform, NonGaussianShape::kMixture}) {
      PixelNoiseOptions o;
      o.kind = kind;
      o.shape = shape;
      o.sigma_px = 0.8;
      const auto e = pixelErrors(o, 11);
      ASSERT_GT(e.size(), 5000u);
      const double n = static_cast<double>(e.size());
      Eigen::Vector4d mean = Eigen::Vector4d::Zero(), m2 = Eigen::Vector4d::Zero(),
                      m4 = Eigen::Vector4d::Zero();
      for (const auto& x : e) mean += x / n;
      for (const auto& x : e) {
        const Eigen::Vector4d d = x - mean;
        m2 += d.cwiseProduct(d) / n;
        m4 += d.cwiseProduct(d).cwiseProduct(d).cwiseProduct(d) / n;
      }
      const Eigen::Vector4d expected_mean =
          kind == NoiseKind::kNonCentred ? o.bias_px : Eigen::Vector4d::Zero();
      SCOPED_TRACE(name + (shape == NonGaussianShape::kUniform ? " uniform" : " mixture"));
      for (int k = 0; k < 4; ++k) {
        EXPECT_NEAR(mean(k), expected_mean(k), 5 * 0.8 / std::sqrt(n));
        EXPECT_NEAR(std::sqrt(m2(k)), 0.8, 0.05 * 0.8);
        // Kurtosis tells the shapes apart: Gaussian 3, uniform 1.8, mixture 79.5/6.25 ≈ 12.7.
        const double kurt = m4(k) / (m2(k) * m2(k));
        if (kind != NoiseKind::kNonGaussianCentred) {
          EXPECT_NEAR(kurt, 3.0, 0.3);
        } else if (shape == NonGaussianShape::kUniform) {
          EXPECT_NEAR(kurt, 1.8, 0.1);
        } else {
          EXPECT_GT(kurt, 5.0);
        }
      }
    }
  }
}

TEST(SimObservation, OutliersAndFeatureCap) {
  PixelNoiseOptions o;
  o.sigma_px = 0.1;
  o.outlier_rate = 0.2;
  const auto e = pixelErrors(o, 12);
  int far = 0;
  for (const auto& x : e) far += x.cwiseAbs().maxCoeff() > 1.0;
  EXPECT_NEAR(far / static_cast<double>(e.size()), 0.2, 0.03);

  const World w = makeWorld(3.0);
  auto traj = circle();
  for (FeatureCap cap : {FeatureCap::kNearest, FeatureCap::kRandom}) {
    PixelNoiseOptions c;
    c.max_features = 10;
    c.cap = cap;
    ObservationSimulator capped(StereoCameraOptions{}, c, 1);
    ObservationSimulator full(StereoCameraOptions{}, PixelNoiseOptions{}, 1);
    const TrajectoryState s = traj->state(3.0);
    const auto a = capped.observe(0, s, w), b = full.observe(0, s, w);
    ASSERT_GT(b.observations.size(), 10u);
    EXPECT_EQ(a.observations.size(), 10u);
    if (cap == FeatureCap::kNearest) {
      // The kept ones are the 10 nearest of all visible.
      const auto range = [&](uint32_t id) {
        return full.camera().landmarkInCamera(s.p_BinN, s.euler, w.landmarks()[id].p_LinN).norm();
      };
      std::vector<double> all;
      for (const auto& ob : b.observations) all.push_back(range(ob.index));
      std::sort(all.begin(), all.end());
      for (const auto& ob : a.observations) EXPECT_LE(range(ob.index), all[9] + 1e-12);
    }
  }
}

TEST(SimObservation, DeterministicPerSeed) {
  PixelNoiseOptions o;
  o.outlier_rate = 0.05;
  const auto a = pixelErrors(o, 77), b = pixelErrors(o, 77), c = pixelErrors(o, 78);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]);
  ASSERT_EQ(a.size(), c.size());
  EXPECT_NE(a[0], c[0]);
}

}  // namespace
}  // namespace cvslam::sim
