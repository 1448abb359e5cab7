#include "cvslam/slam/k_nearest_map_manager.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/io/config_node.h"
#include "cvslam/slam/landmark_archive.h"

namespace cvslam {
namespace {

std::vector<MapCandidate> lineOfCandidates(int n) {
  std::vector<MapCandidate> c;
  for (int i = 0; i < n; ++i) c.push_back({100 + i, Eigen::Vector3d(i, 0, 0)});
  return c;
}

TEST(KNearestMapManager, KeepsTheKNearestToVirtualPoint) {
  MapManagerOptions o;
  o.k = 3;
  KNearestMapManager mm(o);
  auto ids = mm.select(lineOfCandidates(10), Eigen::Vector3d(6.2, 0, 0));
  EXPECT_EQ(ids, (std::vector<int64_t>{105, 106, 107}));
}

TEST(KNearestMapManager, ReobservedArchivedLandmarksComeFirst) {
  // More observed candidates than k: a re-observed archived landmark far from m* (a loop
  // landmark after a drift) still gets its place, ahead of nearer observed ones.
  MapManagerOptions o;
  o.k = 3;
  std::vector<MapCandidate> c = lineOfCandidates(6);
  for (MapCandidate& m : c) m.observed = true;
  c.push_back({900, Eigen::Vector3d(40, 0, 0), true, true});
  auto ids = KNearestMapManager(o).select(c, Eigen::Vector3d::Zero());
  EXPECT_EQ(ids, (std::vector<int64_t>{100, 101, 900}));
}

TEST(KNearestMapManager, FewerCandidatesThanKKeepsAll) {
  MapManagerOptions o;
  o.k = 20;
  auto ids = KNearestMapManager(o).select(lineOfCandidates(4), Eigen::Vector3d::Zero());
  EXPECT_EQ(ids.size(), 4u);
}

TEST(KNearestMapManager, FullMapKeepsEverything) {
  MapManagerOptions o;
  o.kind = MapKind::kFull;
  o.k = 2;
  auto ids = KNearestMapManager(o).select(lineOfCandidates(50), Eigen::Vector3d::Zero());
  EXPECT_EQ(ids.size(), 50u);
}

TEST(KNearestMapManager, FullMapBeyondItsBoundArchivesTheLeastRecentlyObserved) {
  MapManagerOptions o;
  o.kind = MapKind::kFull;
  o.max_landmarks = 4;
  std::vector<MapCandidate> c = lineOfCandidates(8);
  // Last seen: 100 at 8 s, 101 at 7 s, ..., 107 at 1 s; 107 is observed now, so it stays.
  for (std::size_t i = 0; i < c.size(); ++i)
    c[i].last_seen_us = (8 - static_cast<int64_t>(i)) * 1000000;
  c[7].observed = true;
  // m* at 107: the nearest would be 104–107, the most recently observed are 100–102.
  auto ids = KNearestMapManager(o).select(c, Eigen::Vector3d(7, 0, 0));
  EXPECT_EQ(ids, (std::vector<int64_t>{100, 101, 102, 107}));
  o.max_landmarks = 0;  // no bound
  EXPECT_EQ(KNearestMapManager(o).select(c, Eigen::Vector3d::Zero()).size(), 8u);
}

TEST(KNearestMapManager, VirtualPointLiesBelowADownwardCamera) {
  StereoCamera cam;  // default: looking down, baseline 0.2 m along the right wing
  const Eigen::Vector3d p(10, 20, -10), euler(0, 0, 0);
  const Eigen::Vector3d m =
      KNearestMapManager::virtualPoint(cam, p, rotationBodyToNav(euler), 10.0);
  EXPECT_TRUE(m.isApprox(Eigen::Vector3d(10, 20.1, 0), 1e-12)) << m.transpose();
  // Heading east: the baseline (right wing) now points south.
  const Eigen::Vector3d m_east = KNearestMapManager::virtualPoint(
      cam, p, rotationBodyToNav(Eigen::Vector3d(0, 0, M_PI / 2)), 10.0);
  EXPECT_TRUE(m_east.isApprox(Eigen::Vector3d(9.9, 20, 0), 1e-12)) << m_east.transpose();
}

TEST(KNearestMapManager, SceneDepthIsAQuantileOfObserved) {
  KNearestMapManager mm;  // the 0.1 quantile
  EXPECT_DOUBLE_EQ(mm.sceneDepth({}), 10.0);
  EXPECT_DOUBLE_EQ(mm.sceneDepth({3, 100, 7}), 3.0);
  EXPECT_DOUBLE_EQ(mm.sceneDepth({9, 8, 7, 6, 5, 4, 3, 2, 1, 100, 11, 12}), 2.0);
  MapManagerOptions median;
  median.scene_depth_quantile = 0.5;
  EXPECT_DOUBLE_EQ(KNearestMapManager(median).sceneDepth({3, 100, 7}), 7.0);
  median.scene_depth_quantile = 1.0;
  EXPECT_DOUBLE_EQ(KNearestMapManager(median).sceneDepth({3, 100, 7}), 100.0);
  MapManagerOptions o;
  o.use_observed_depth = false;
  EXPECT_DOUBLE_EQ(KNearestMapManager(o).sceneDepth({3, 100, 7}), 10.0);
}

TEST(KNearestMapManager, OptionsLoadAndValidate) {
  auto cfg = ConfigNode::fromString("map: {kind: full, k: 5}", "a.yaml");
  MapManagerOptions o;
  ASSERT_TRUE(o.load(cfg->child("map")).ok());
  EXPECT_EQ(o.kind, MapKind::kFull);
  EXPECT_EQ(o.k, 5);
  EXPECT_EQ(o.max_landmarks, 1000);
  auto bounded = ConfigNode::fromString("map: {kind: full, max_landmarks: 300}", "a.yaml");
  ASSERT_TRUE(o.load(bounded->child("map")).ok());
  EXPECT_EQ(o.max_landmarks, 300);
  auto negative = ConfigNode::fromString("map: {max_landmarks: -1}", "a.yaml");
  EXPECT_FALSE(MapManagerOptions().load(negative->child("map")).ok());
  auto quantile = ConfigNode::fromString("map: {scene_depth_quantile: 1.5}", "a.yaml");
  EXPECT_FALSE(MapManagerOptions().load(quantile->child("map")).ok());
  auto bad = ConfigNode::fromString("map: {kind: sparse, k: 0}", "a.yaml");
  EXPECT_FALSE(MapManagerOptions().load(bad->child("map")).ok());
}

TEST(LandmarkArchive, StoreTakeRoundTrip) {
  LandmarkArchive archive;
  ArchivedLandmark lm;
  lm.index = 7;
  lm.p_LinN = Eigen::Vector3d(1, 2, 3);
  lm.covariance = Eigen::Matrix3d::Identity() * 0.5;
  archive.store(42, lm);
  EXPECT_TRUE(archive.contains(42));
  ASSERT_NE(archive.find(42), nullptr);
  auto back = archive.take(42);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->p_LinN, lm.p_LinN);
  EXPECT_FALSE(archive.contains(42));
  EXPECT_FALSE(archive.take(42).has_value());
}

TEST(LandmarkArchive, IndexesLandmarksByFeatureIndex) {
  LandmarkArchive archive;
  ArchivedLandmark lm;
  lm.index = 7;
  archive.store(1, lm);
  archive.store(2, lm);
  lm.index = 9;
  archive.store(3, lm);
  auto sorted = [](std::vector<int64_t> v) {
    std::sort(v.begin(), v.end());
    return v;
  };
  EXPECT_EQ(sorted(archive.withIndex(7)), (std::vector<int64_t>{1, 2}));
  EXPECT_EQ(archive.withIndex(9), (std::vector<int64_t>{3}));
  EXPECT_TRUE(archive.withIndex(8).empty());
  archive.store(1, lm);  // replaced with index 9: moves bucket
  EXPECT_EQ(archive.withIndex(7), (std::vector<int64_t>{2}));
  EXPECT_EQ(sorted(archive.withIndex(9)), (std::vector<int64_t>{1, 3}));
  ASSERT_TRUE(archive.take(2).has_value());  // re-activated: leaves the index
  EXPECT_TRUE(archive.withIndex(7).empty());
}

}  // namespace
}  // namespace cvslam
