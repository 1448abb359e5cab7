// Visual vocabulary of the feature index (docs/conventions.md): same input ⇒ same word ids on every
// agent; save/load round trip; the shipped file; corrupt files are reported.

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>

#include "cvslam/vision/feature_detector.h"
#include "cvslam/vision/vocabulary.h"
#include "vision_test_data.h"

namespace cvslam::vision {
namespace {

std::string tempPath(const std::string& name) {
  return std::string(CVSLAM_BINARY_DIR) + "/test_vision_vocabulary_" + name;
}

std::string readBytes(const std::string& path) {
  std::ifstream is(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>());
}

Features featuresOfFrame(std::size_t k) {
  const auto stamps = test::eurocStereoStamps();
  Features f;
  cv::Mat l, r;
  if (stamps.size() <= k || !test::loadEurocPair(stamps[k], &l, &r)) return f;
  auto det = makeFeatureDetector(DetectorOptions{});
  if (det.ok()) (void)(*det)->detect(l, &f);
  return f;
}

TEST(VisionVocabulary, TrainingAndLookupAreDeterministic) {
  const Features a = featuresOfFrame(0);
  const Features b = featuresOfFrame(40);
  ASSERT_GT(a.size(), 100u) << "EuRoC micro data missing under " << test::sharedDataDir();
  cv::Mat train;
  train.push_back(a.descriptors);
  train.push_back(b.descriptors);
  VocabularyOptions o;
  o.branching = 8;
  o.depth = 2;
  auto v1 = Vocabulary::train(train, DescriptorType::kSift, o);
  auto v2 = Vocabulary::train(train.clone(), DescriptorType::kSift, o);
  ASSERT_TRUE(v1.ok() && v2.ok());
  EXPECT_EQ(v1->wordCount(), 64);
  const Features c = featuresOfFrame(80);  // not used in training
  const auto w1 = v1->words(c);
  EXPECT_EQ(w1, v2->words(c));
  ASSERT_EQ(w1.size(), c.size());
  std::vector<int> hist(64, 0);
  for (uint32_t w : w1) {
    ASSERT_LT(w, 64u);
    ++hist[w];
  }
  // Words are used, not collapsed into a few.
  EXPECT_GT(std::count_if(hist.begin(), hist.end(), [](int n) { return n > 0; }), 40);
  ASSERT_TRUE(v1->save(tempPath("a.cvoc")).ok());
  ASSERT_TRUE(v2->save(tempPath("b.cvoc")).ok());
  EXPECT_EQ(readBytes(tempPath("a.cvoc")), readBytes(tempPath("b.cvoc")));  // byte-identical
  // Round trip, as two agents loading the same file.
  auto agent1 = Vocabulary::load(tempPath("a.cvoc"));
  auto agent2 = Vocabulary::load(tempPath("a.cvoc"));
  ASSERT_TRUE(agent1.ok()) << agent1.status().message();
  ASSERT_TRUE(agent2.ok());
  EXPECT_EQ(agent1->words(c), w1);
  EXPECT_EQ(agent2->words(c), w1);
  // A different seed gives a different vocabulary (the seed is really used).
  o.seed += 1;
  auto v3 = Vocabulary::train(train, DescriptorType::kSift, o);
  ASSERT_TRUE(v3.ok());
  EXPECT_NE(v3->words(c), w1);
  std::remove(tempPath("a.cvoc").c_str());
  std::remove(tempPath("b.cvoc").c_str());
}

TEST(VisionVocabulary, OrbVocabulary) {
  Features f;
  cv::Mat l, r;
  const auto stamps = test::eurocStereoStamps();
  ASSERT_FALSE(stamps.empty());
  ASSERT_TRUE(test::loadEurocPair(stamps[0], &l, &r));
  DetectorOptions d;
  d.type = DetectorType::kOrb;
  auto det = makeFeatureDetector(d);
  ASSERT_TRUE(det.ok());
  ASSERT_TRUE((*det)->detect(l, &f).ok());
  VocabularyOptions o;
  o.branching = 6;
  auto v = Vocabulary::train(f.descriptors, DescriptorType::kOrb, o);
  ASSERT_TRUE(v.ok()) << v.status().message();
  EXPECT_EQ(v->wordCount(), 36);
  const auto w = v->words(f);
  EXPECT_EQ(w.size(), f.size());
  EXPECT_TRUE(v->words(featuresOfFrame(0)).empty());  // SIFT features: type mismatch
}

TEST(VisionVocabulary, ShippedVocabularyLoadsAndIsSmall) {
  const std::string path = test::sourceDir() + "/config/vocabulary_sift.cvoc";
  auto v = Vocabulary::load(path);
  ASSERT_TRUE(v.ok()) << v.status().message();
  EXPECT_EQ(v->type(), DescriptorType::kSift);
  EXPECT_GE(v->wordCount(), 256);
  EXPECT_LT(readBytes(path).size(), 1000000u);
  const Features c = featuresOfFrame(10);
  for (uint32_t w : v->words(c)) EXPECT_LT(w, static_cast<uint32_t>(v->wordCount()));
}

TEST(VisionVocabulary, BadFilesAndInputsAreErrors) {
  EXPECT_FALSE(Vocabulary::load(tempPath("missing.cvoc")).ok());
  {
    std::ofstream os(tempPath("junk.cvoc"), std::ios::binary);
    os << "not a vocabulary at all";
  }
  auto junk = Vocabulary::load(tempPath("junk.cvoc"));
  ASSERT_FALSE(junk.ok());
  EXPECT_NE(junk.status().message().find("not a cvslam vocabulary"), std::string::npos);
  // Truncated copy of the shipped file.
  const std::string full = readBytes(test::sourceDir() + "/config/vocabulary_sift.cvoc");
  ASSERT_GT(full.size(), 1000u);
  {
    std::ofstream os(tempPath("cut.cvoc"), std::ios::binary);
    os << full.substr(0, full.size() / 2);
  }
  auto cut = Vocabulary::load(tempPath("cut.cvoc"));
  ASSERT_FALSE(cut.ok());
  EXPECT_NE(cut.status().message().find("truncated"), std::string::npos);
  std::remove(tempPath("junk.cvoc").c_str());
  std::remove(tempPath("cut.cvoc").c_str());
  EXPECT_FALSE(Vocabulary::train(cv::Mat::zeros(100, 64, CV_8U), DescriptorType::kSift, {}).ok());
  EXPECT_FALSE(Vocabulary::train(cv::Mat::zeros(3, 128, CV_8U), DescriptorType::kSift, {}).ok());
}

}  // namespace
}  // namespace cvslam::vision
