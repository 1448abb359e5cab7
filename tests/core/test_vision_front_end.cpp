// StereoFrontEnd (docs/front_end.md) on the real rectified EuRoC pair, and association of its
// observations to predicted landmarks (descriptor + Mahalanobis gate).

#include <gtest/gtest.h>

#include <memory>
#include <set>

#include "cvslam/io/config_node.h"
#include "cvslam/vision/map_association.h"
#include "cvslam/vision/stereo_front_end.h"
#include "cvslam/vision/stereo_rectifier.h"
#include "vision_test_data.h"

namespace cvslam::vision {
namespace {

struct RealRun {
  std::vector<StereoObservation> obs;
  RectifiedStereo rect;
  int words = 0;
};

RealRun runFrontEnd(DetectorType type, std::size_t frame) {
  RealRun run;
  StereoCalibration calib;
  if (!test::eurocCalibration(&calib)) return run;
  auto rect = StereoRectifier::create(calib);
  if (!rect.ok()) return run;
  run.rect = rect->rectified();
  StereoFrontEndOptions o;
  o.detector.type = type;
  o.stereo.focal_px = run.rect.f;
  o.stereo.baseline_m = run.rect.baseline;
  std::shared_ptr<const Vocabulary> vocab;
  if (type != DetectorType::kOrb) {
    auto v = Vocabulary::load(test::sourceDir() + "/config/vocabulary_sift.cvoc");
    if (!v.ok()) return run;
    run.words = v->wordCount();
    vocab = std::make_shared<const Vocabulary>(std::move(v.value()));
  }
  auto fe = StereoFrontEnd::create(o, vocab);
  if (!fe.ok()) return run;
  const auto stamps = test::eurocStereoStamps();
  cv::Mat l, r, lr, rr;
  if (stamps.size() <= frame || !test::loadEurocPair(stamps[frame], &l, &r)) return run;
  if (!rect->rectify(l, r, &lr, &rr).ok()) return run;
  EXPECT_TRUE(fe->process(lr, rr, &run.obs).ok());
  return run;
}

TEST(VisionFrontEnd, RealPairGivesStereoObservations) {
  const RealRun run = runFrontEnd(DetectorType::kAdaptiveSift, 5);
  ASSERT_GT(run.obs.size(), 100u) << "EuRoC data or vocabulary missing";
  std::set<uint32_t> words;
  for (const StereoObservation& o : run.obs) {
    EXPECT_EQ(o.type, ObservationType::kNew);
    EXPECT_EQ(o.landmark_id, -1);
    EXPECT_EQ(o.descriptor.size(), 128u);
    EXPECT_LT(o.index, static_cast<uint32_t>(run.words));
    const double d = o.z[0] - o.z[2];
    EXPECT_GT(d, 0.0);
    EXPECT_LE(d, run.rect.f * run.rect.baseline / 0.5);  // default z_min = 0.5 m
    EXPECT_LE(std::abs(o.z[1] - o.z[3]), 2.0);
    words.insert(o.index);
  }
  EXPECT_GT(words.size(), run.obs.size() / 4);  // indices spread over the vocabulary
  const RealRun orb = runFrontEnd(DetectorType::kOrb, 5);
  EXPECT_GT(orb.obs.size(), 100u);
  for (const StereoObservation& o : orb.obs) EXPECT_EQ(o.descriptor.size(), 32u);
}

TEST(VisionFrontEnd, CreateChecksOptions) {
  StereoFrontEndOptions o;
  EXPECT_FALSE(StereoFrontEnd::create(o, nullptr).ok());  // no focal length / baseline
  o.stereo.focal_px = 450;
  o.stereo.baseline_m = 0.11;
  EXPECT_TRUE(StereoFrontEnd::create(o, nullptr).ok());
  o.detector.type = DetectorType::kOrb;
  auto v = Vocabulary::load(test::sourceDir() + "/config/vocabulary_sift.cvoc");
  ASSERT_TRUE(v.ok());
  auto fe = StereoFrontEnd::create(o, std::make_shared<const Vocabulary>(std::move(v.value())));
  EXPECT_FALSE(fe.ok());  // SIFT vocabulary with ORB detector
  auto cfg = ConfigNode::fromString(
      "front_end: {detector: {type: sift}, stereo: {focal_px: 400, baseline_m: 0.2, match: "
      "{norm: angle, dist_ratio: 0.7}}, max_observations: 50}",
      "fe.yaml");
  ASSERT_TRUE(cfg.ok());
  StereoFrontEndOptions loaded;
  ASSERT_TRUE(loaded.load(cfg->child("front_end")).ok()) << cfg->status().message();
  EXPECT_EQ(loaded.detector.type, DetectorType::kSift);
  EXPECT_EQ(loaded.stereo.match.norm, MatchNorm::kAngle);
  EXPECT_DOUBLE_EQ(loaded.stereo.match.dist_ratio, 0.7);
  EXPECT_EQ(loaded.max_observations, 50);
  EXPECT_TRUE(cfg->finish().ok()) << cfg->finish().message();
}

TEST(VisionFrontEnd, ShippedConfigMatchesDefaults) {
  auto cfg = ConfigNode::loadFile(test::sourceDir() + "/config/front_end.yaml");
  ASSERT_TRUE(cfg.ok()) << cfg.status().message();
  StereoFrontEndOptions o;
  ASSERT_TRUE(o.load(cfg->child("front_end")).ok()) << cfg->status().message();
  EXPECT_TRUE(cfg->finish().ok()) << cfg->finish().message();  // no unknown keys
  const StereoFrontEndOptions d;
  EXPECT_EQ(o.detector.type, d.detector.type);
  EXPECT_DOUBLE_EQ(o.detector.adaptive_sift.energy_low, d.detector.adaptive_sift.energy_low);
  EXPECT_DOUBLE_EQ(o.detector.adaptive_sift.energy_high, d.detector.adaptive_sift.energy_high);
  EXPECT_EQ(o.detector.adaptive_sift.max_features, d.detector.adaptive_sift.max_features);
  EXPECT_EQ(o.detector.adaptive_sift.upsample_first_octave,
            d.detector.adaptive_sift.upsample_first_octave);
  EXPECT_EQ(o.detector.orb_max_features, d.detector.orb_max_features);
  EXPECT_DOUBLE_EQ(o.stereo.min_depth_m, d.stereo.min_depth_m);
  EXPECT_DOUBLE_EQ(o.stereo.match.dist_ratio, d.stereo.match.dist_ratio);
  EXPECT_EQ(o.stereo.match.norm, d.stereo.match.norm);
}

TEST(VisionAssociation, OptionsLoadAndErrors) {
  auto cfg = ConfigNode::fromString(
      "association: {descriptor_type: orb, gate_chi2: 9.49, max_descriptor_distance: 60, "
      "dist_ratio: 0.7}",
      "a.yaml");
  ASSERT_TRUE(cfg.ok());
  MapAssociationOptions o;
  ASSERT_TRUE(o.load(cfg->child("association")).ok()) << cfg->status().message();
  EXPECT_EQ(o.descriptor_type, DescriptorType::kOrb);
  EXPECT_DOUBLE_EQ(o.gate_chi2, 9.49);
  EXPECT_TRUE(cfg->finish().ok());
  for (const char* bad :
       {"{gate_chi2: -1}", "{dist_ratio: 1.5}", "{norm: manhattan}", "{descriptor_type: surf}"}) {
    auto c = ConfigNode::fromString(std::string("association: ") + bad, "a.yaml");
    ASSERT_TRUE(c.ok());
    MapAssociationOptions x;
    const Status s = x.load(c->child("association"));
    EXPECT_FALSE(s.ok()) << bad;
    EXPECT_EQ(s.message().rfind("a.yaml: association.", 0), 0u) << s.message();
  }
  auto m = ConfigNode::fromString("match: {dist_ratio: 0}", "m.yaml");
  ASSERT_TRUE(m.ok());
  MatchOptions mo;
  EXPECT_FALSE(mo.load(m->child("match")).ok());
}

TEST(VisionAssociation, GateAndDescriptorDecide) {
  RealRun run = runFrontEnd(DetectorType::kAdaptiveSift, 5);
  ASSERT_GT(run.obs.size(), 60u);
  std::vector<StereoObservation>& obs = run.obs;
  // Predictions for the first 40 observations: ẑ off by ≈ 1.5 px, S = 4 px² I.
  std::vector<LandmarkPrediction> pred;
  for (int k = 0; k < 40; ++k) {
    LandmarkPrediction p;
    p.landmark_id = 1000 + k;
    p.z = obs[static_cast<std::size_t>(k)].z + Eigen::Vector4d(1.5, -1.0, 1.0, -1.0);
    p.S = 4.0 * Eigen::Matrix4d::Identity();
    p.descriptor = obs[static_cast<std::size_t>(k)].descriptor;
    pred.push_back(p);
  }
  // Landmark 2000: right place of observation 40, but another feature's descriptor.
  LandmarkPrediction wrong_desc;
  wrong_desc.landmark_id = 2000;
  wrong_desc.z = obs[40].z;
  wrong_desc.S = 4.0 * Eigen::Matrix4d::Identity();
  wrong_desc.descriptor = obs[50].descriptor;
  pred.push_back(wrong_desc);
  // Landmark 3000: observation 41's descriptor, predicted 30 px away (outside the gate).
  LandmarkPrediction far_away;
  far_away.landmark_id = 3000;
  far_away.z = obs[41].z + Eigen::Vector4d(30, 0, 30, 0);
  far_away.S = 4.0 * Eigen::Matrix4d::Identity();
  far_away.descriptor = obs[41].descriptor;
  pred.push_back(far_away);
  // Landmark 4000: non-invertible S is skipped, not a crash.
  LandmarkPrediction singular = pred[0];
  singular.landmark_id = 4000;
  singular.S.setZero();
  pred.push_back(singular);

  MapAssociationOptions o;
  AssociationStats stats;
  ASSERT_TRUE(associateToMap(pred, o, &obs, &stats).ok());
  for (int k = 0; k < 40; ++k) {
    EXPECT_EQ(obs[static_cast<std::size_t>(k)].type, ObservationType::kReobserved) << k;
    EXPECT_EQ(obs[static_cast<std::size_t>(k)].landmark_id, 1000 + k);
  }
  for (std::size_t k = 40; k < obs.size(); ++k) {
    EXPECT_EQ(obs[k].type, ObservationType::kNew) << k;
    EXPECT_EQ(obs[k].landmark_id, -1);
  }
  EXPECT_EQ(stats.associated, 40);
  EXPECT_GE(stats.candidates_gated, 41);
  // The ground station may mark an observation as seen by another UAV (type 2).
  obs[45].type = ObservationType::kSeenByOther;
  EXPECT_EQ(static_cast<int>(obs[45].type), 2);
  // A larger innovation covariance lets the far prediction in.
  far_away.S = 400.0 * Eigen::Matrix4d::Identity();
  ASSERT_TRUE(associateToMap({far_away}, o, &obs).ok());
  EXPECT_EQ(obs[41].landmark_id, 3000);
}

}  // namespace
}  // namespace cvslam::vision
