#include "cvslam/slam/appearance_loop_detector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvslam/io/config_node.h"

namespace cvslam {
namespace {

constexpr int kBytes = 128;  // SIFT descriptors
constexpr double kDeg = M_PI / 180.0;

std::vector<uint8_t> randomDescriptor(std::mt19937& rng) {
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<uint8_t> d(kBytes);
  for (uint8_t& b : d) b = static_cast<uint8_t>(byte(rng));
  return d;
}

/// The same descriptor as seen again: each byte moved by up to ±3.
std::vector<uint8_t> perturbed(const std::vector<uint8_t>& d, std::mt19937& rng) {
  std::uniform_int_distribution<int> step(-3, 3);
  std::vector<uint8_t> out = d;
  for (uint8_t& b : out) b = static_cast<uint8_t>(std::clamp(b + step(rng), 0, 255));
  return out;
}

StereoCamera::Vector9d pose(double x, double y, double z, double yaw) {
  StereoCamera::Vector9d v = StereoCamera::Vector9d::Zero();
  v << x, y, z, 0, 0, 0, 0.02, -0.01, yaw;
  return v;
}

/// A downward camera over flat, slightly rough ground: landmarks seen at the true pose, an
/// archive that stored them (last seen long ago), and the current frame's observations.
struct LoopScene {
  StereoCamera camera;
  StereoCamera::Vector9d x_true = pose(50.0, -20.0, -10.0, 0.4);
  std::vector<Eigen::Vector3d> points;
  std::vector<std::vector<uint8_t>> descriptors;
  LandmarkArchive archive;
  std::vector<StereoObservation> observations;
  static constexpr int64_t kNow = 200'000'000;  // t = 200 s

  explicit LoopScene(int n_landmarks, uint32_t seed = 5) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-4.0, 4.0), h(-0.3, 0.3);
    while (static_cast<int>(points.size()) < n_landmarks) {
      const Eigen::Vector3d p(x_true(0) + u(rng), x_true(1) + u(rng), h(rng));
      const Eigen::Vector3d p_C = camera.landmarkInCamera(x_true.head<3>(), x_true.tail<3>(), p);
      if (!camera.isVisible(p_C)) continue;
      points.push_back(p);
      descriptors.push_back(randomDescriptor(rng));
    }
    std::normal_distribution<double> pixel(0.0, 0.1);
    for (std::size_t i = 0; i < points.size(); ++i) {
      ArchivedLandmark a;
      a.index = static_cast<uint32_t>(i % 5);  // several landmarks share each word
      a.p_LinN = points[i];
      a.first_seen_us = 1'000'000;
      a.last_seen_us = 2'000'000;
      a.archived_us = 3'000'000;
      a.descriptor = descriptors[i];
      archive.store(static_cast<int64_t>(1000 + i), a);
      StereoObservation obs;
      obs.index = a.index;
      obs.z = camera.project(x_true, points[i]);
      for (int k = 0; k < 4; ++k) obs.z(k) += pixel(rng);
      obs.z(2) = obs.z(0) - (camera.project(x_true, points[i])(0) -
                             camera.project(x_true, points[i])(2));  // exact disparity
      obs.descriptor = perturbed(descriptors[i], rng);
      observations.push_back(obs);
    }
  }

  LoopQuery query(const StereoCamera::Vector9d& x_estimate) const {
    LoopQuery q;
    q.t_us = kNow;
    q.x_v = EstimatedPose::fromEuler(x_estimate);
    q.position_sigma_m = 2.0;  // search radius 20 m, corrections up to 7 m (3.5 σ)
    return q;
  }
};

TEST(AppearanceLoopDetector, FindsTheLoopAndTheDriftOfTheVehicle) {
  LoopScene scene(30);
  // The filter has drifted: 6 m north-west, 0.8 m up and 3° of yaw.
  const StereoCamera::Vector9d x_drifted =
      pose(scene.x_true(0) - 4.0, scene.x_true(1) + 4.5, -10.8, scene.x_true(8) + 3.0 * kDeg);
  // Distractors: unrelated archived landmarks in the same words, and unseen observations.
  std::mt19937 rng(11);
  for (int i = 0; i < 40; ++i) {
    ArchivedLandmark a;
    a.index = static_cast<uint32_t>(i % 5);
    a.p_LinN = Eigen::Vector3d(scene.x_true(0) + i % 7, scene.x_true(1) - i % 3, 0.0);
    a.descriptor = randomDescriptor(rng);
    scene.archive.store(5000 + i, a);
  }
  std::vector<StereoObservation> observations = scene.observations;
  for (int i = 0; i < 10; ++i) {
    StereoObservation extra = scene.observations[static_cast<std::size_t>(i)];
    extra.z(0) += 7.0;
    extra.z(2) += 7.0;
    extra.descriptor = randomDescriptor(rng);
    observations.push_back(extra);
  }
  observations[0].landmark_id = 7;     // associated to a landmark not in the archive: skipped
  observations[1].landmark_id = 1001;  // gated association to its loop landmark: verified too

  AppearanceLoopDetector detector;
  const LoopDetection d =
      detector.detect(observations, scene.camera, scene.archive, scene.query(x_drifted));
  ASSERT_TRUE(d.detected) << d.candidates << " candidates, " << d.inliers << " inliers";
  EXPECT_EQ(d.matches.size(), scene.points.size() - 1);
  for (const auto& [i, id] : d.matches) {
    EXPECT_NE(i, 0u);  // (observation 1 stays: gated to the right landmark)
    EXPECT_EQ(id, static_cast<int64_t>(1000 + i));  // every match is the right landmark
  }
  // The alignment undoes the drift: it carries the drifted vehicle onto the true one.
  EXPECT_NEAR(d.alignment.yaw, -3.0 * kDeg, 0.2 * kDeg);
  EXPECT_LT((d.alignment.apply(x_drifted.head<3>()) - scene.x_true.head<3>()).norm(), 0.1);
  EXPECT_LT(d.alignment.rms_residual, 0.1);
}

TEST(AppearanceLoopDetector, RejectsMatchesWithoutConsistentGeometry) {
  LoopScene scene(30);
  // The same appearance, but every archived landmark sits where another one is: the
  // descriptors match, no rigid motion explains them.
  LandmarkArchive shuffled;
  std::mt19937 rng(3);
  std::vector<Eigen::Vector3d> places = scene.points;
  std::shuffle(places.begin(), places.end(), rng);
  for (const auto& [id, a] : scene.archive.all()) {
    ArchivedLandmark moved = a;
    moved.p_LinN = places[static_cast<std::size_t>(id - 1000)] + Eigen::Vector3d(0, 0, 0.5);
    shuffled.store(id, moved);
  }
  AppearanceLoopDetector detector;
  const LoopDetection d =
      detector.detect(scene.observations, scene.camera, shuffled, scene.query(scene.x_true));
  EXPECT_EQ(d.candidates, 30);  // appearance alone would accept them all
  EXPECT_FALSE(d.detected) << d.inliers << " inliers";
  EXPECT_TRUE(d.matches.empty());
  EXPECT_LT(d.inliers, 6);
}

TEST(AppearanceLoopDetector, RejectsALargeYawOrOffset) {
  LoopScene scene(30);
  AppearanceLoopDetector detector;
  // 40° of yaw drift: geometrically consistent, but beyond max_yaw_deg.
  const LoopDetection yawed = detector.detect(
      scene.observations, scene.camera, scene.archive,
      scene.query(pose(scene.x_true(0), scene.x_true(1), -10, scene.x_true(8) + 40 * kDeg)));
  EXPECT_GE(yawed.inliers, 25);
  EXPECT_FALSE(yawed.detected);
  // 80 m off: the archived landmarks are outside the search radius, not even candidates.
  const LoopDetection far = detector.detect(
      scene.observations, scene.camera, scene.archive,
      scene.query(pose(scene.x_true(0) + 80, scene.x_true(1), -10, scene.x_true(8))));
  EXPECT_EQ(far.candidates, 0);
  EXPECT_FALSE(far.detected);
}

TEST(AppearanceLoopDetector, ALookAlikePlaceBeyondTheSearchRadiusIsNoLoop) {
  // The archive holds the same-looking place 30 m away (repetitive ground): appearance and
  // rigid geometry agree perfectly, only the position prior can reject it.
  LoopScene scene(30);
  LandmarkArchive elsewhere;
  for (const auto& [id, a] : scene.archive.all()) {
    ArchivedLandmark moved = a;
    moved.p_LinN += Eigen::Vector3d(30.0, 0.0, 0.0);
    elsewhere.store(id, moved);
  }
  AppearanceLoopDetector detector;
  LoopQuery confident = scene.query(scene.x_true);  // σ 2 m: searched within 20 m
  EXPECT_EQ(detector.detect(scene.observations, scene.camera, elsewhere, confident).candidates, 0);
  LoopQuery unsure = confident;  // σ 4 m: searched within 40 m, but 30 m is 7.5 σ
  unsure.position_sigma_m = 4.0;
  const LoopDetection rejected =
      detector.detect(scene.observations, scene.camera, elsewhere, unsure);
  EXPECT_GE(rejected.inliers, 25);
  EXPECT_FALSE(rejected.detected);
  LoopQuery lost = confident;  // σ 10 m: 30 m is within 3.5 σ, and the look-alike is taken
  lost.position_sigma_m = 10.0;
  const LoopDetection d = detector.detect(scene.observations, scene.camera, elsewhere, lost);
  ASSERT_TRUE(d.detected);
  EXPECT_NEAR(d.alignment.translation.x(), 30.0, 0.1);
  EXPECT_DOUBLE_EQ(detector.searchRadius(0.1), 5.0);     // min_search_radius_m
  EXPECT_DOUBLE_EQ(detector.searchRadius(100.0), 60.0);  // max_offset_m
}

TEST(AppearanceLoopDetector, NoLoopInANeverSeenSceneOrForRecentLandmarks) {
  LoopScene scene(30);
  std::mt19937 rng(17);
  std::vector<StereoObservation> unseen = scene.observations;
  for (StereoObservation& obs : unseen) obs.descriptor = randomDescriptor(rng);
  AppearanceLoopDetector detector;
  const LoopDetection d =
      detector.detect(unseen, scene.camera, scene.archive, scene.query(scene.x_true));
  EXPECT_EQ(d.candidates, 0);
  EXPECT_FALSE(d.detected);

  // Seen, but too recently to be a loop: the gated association handles those.
  LoopQuery recent = scene.query(scene.x_true);
  recent.t_us = 20'000'000;  // 18 s after they were last seen (< 30 s)
  EXPECT_EQ(detector.detect(scene.observations, scene.camera, scene.archive, recent).candidates, 0);
  // Disabled: nothing.
  LoopDetectionOptions off;
  off.enabled = false;
  EXPECT_FALSE(
      AppearanceLoopDetector(off)
          .detect(scene.observations, scene.camera, scene.archive, scene.query(scene.x_true))
          .detected);
}

TEST(AppearanceLoopDetector, StopWordsAreSkipped) {
  LoopScene scene(30);  // 6 landmarks per word
  LoopDetectionOptions o;
  o.max_word_landmarks = 5;
  EXPECT_EQ(AppearanceLoopDetector(o)
                .detect(scene.observations, scene.camera, scene.archive, scene.query(scene.x_true))
                .candidates,
            0);
}

TEST(AppearanceLoopDetector, OptionsLoadAndValidate) {
  auto cfg = ConfigNode::fromString("loop_detection: {min_inliers: 8, max_yaw_deg: 10}", "a.yaml");
  LoopDetectionOptions o;
  ASSERT_TRUE(o.load(cfg->child("loop_detection")).ok());
  EXPECT_EQ(o.min_inliers, 8);
  EXPECT_DOUBLE_EQ(o.max_yaw_deg, 10.0);
  for (const char* bad : {"{min_inliers: 2}", "{dist_ratio: 1.5}", "{every_n_frames: 0}",
                          "{inlier_distance_m: 0}", "{min_search_radius_m: 10, max_offset_m: 5}"}) {
    auto b = ConfigNode::fromString(std::string("loop_detection: ") + bad, "a.yaml");
    EXPECT_FALSE(LoopDetectionOptions().load(b->child("loop_detection")).ok()) << bad;
  }
}

}  // namespace
}  // namespace cvslam
