#include "cvslam/vision/feature_detector.h"

#include <opencv2/features2d.hpp>

#include "cvslam/io/config_node.h"
#include "cvslam/vision/keypoint_grid.h"

namespace cvslam::vision {

Status DetectorOptions::load(const ConfigNode& node) {
  node.getEnum("type", type,
               {{"adaptive_sift", DetectorType::kAdaptiveSift},
                {"sift", DetectorType::kSift},
                {"orb", DetectorType::kOrb},
                {"fast_sift", DetectorType::kFastSift},
                {"swif", DetectorType::kSwif}});
  adaptive_sift.load(node.child("adaptive_sift"));
  fast_sift.load(node.child("fast_sift"));
  swif.load(node.child("swif"));
  node.get("sift_max_features", sift_max_features);
  node.get("sift_octave_layers", sift_octave_layers);
  node.get("sift_contrast_threshold", sift_contrast_threshold);
  node.get("sift_edge_threshold", sift_edge_threshold);
  node.get("sift_sigma", sift_sigma);
  node.get("orb_max_features", orb_max_features);
  node.get("orb_scale_factor", orb_scale_factor);
  node.get("orb_levels", orb_levels);
  node.get("orb_fast_threshold", orb_fast_threshold);
  node.get("orb_grid_cols", orb_grid_cols);
  node.get("orb_grid_rows", orb_grid_rows);
  node.check(
      orb_grid_cols >= 0 && orb_grid_rows >= 0 && (orb_grid_cols == 0) == (orb_grid_rows == 0),
      "orb_grid_cols", "grid must be 0 × 0 (off) or positive in both directions");
  node.check(sift_max_features >= 0, "sift_max_features", "must be >= 0");
  node.check(sift_octave_layers >= 1, "sift_octave_layers", "must be >= 1");
  node.check(sift_contrast_threshold >= 0, "sift_contrast_threshold", "must be >= 0");
  node.check(sift_sigma > 0, "sift_sigma", "must be > 0");
  node.check(orb_max_features > 0, "orb_max_features", "must be > 0");
  node.check(orb_scale_factor > 1.0, "orb_scale_factor", "must be > 1");
  node.check(orb_levels >= 1, "orb_levels", "must be >= 1");
  node.check(orb_fast_threshold > 0, "orb_fast_threshold", "must be > 0");
  return node.status();
}

DescriptorType descriptorTypeOf(DetectorType type) {
  switch (type) {
    case DetectorType::kOrb:
      return DescriptorType::kOrb;
    case DetectorType::kSwif:
      return DescriptorType::kSwif;
    case DetectorType::kAdaptiveSift:
    case DetectorType::kSift:
    case DetectorType::kFastSift:
      break;
  }
  return DescriptorType::kSift;
}

namespace {

Status checkImage(const cv::Mat& gray) {
  if (gray.empty() || gray.type() != CV_8UC1)
    return Status::Error("feature detector: expected a non-empty 8-bit grey image");
  return Status::Ok();
}

class AdaptiveSiftDetector final : public FeatureDetector {
 public:
  explicit AdaptiveSiftDetector(const AdaptiveSiftOptions& o) : o_(o) {}
  Status detect(const cv::Mat& gray, Features* out) override {
    return detectAdaptiveSift(gray, o_, out);
  }
  DescriptorType descriptorType() const override { return DescriptorType::kSift; }

 private:
  AdaptiveSiftOptions o_;
};

class FastSiftDetector final : public FeatureDetector {
 public:
  explicit FastSiftDetector(const DetectorOptions& o) : sift_(o.adaptive_sift, o.fast_sift) {}
  Status detect(const cv::Mat& gray, Features* out) override {
    return sift_.detectAndDescribe(gray, out);
  }
  DescriptorType descriptorType() const override { return DescriptorType::kSift; }

 private:
  FastSift sift_;
};

class SwifDetector final : public FeatureDetector {
 public:
  explicit SwifDetector(const SwifOptions& o) : swif_(o) {}
  Status detect(const cv::Mat& gray, Features* out) override {
    return swif_.detectAndDescribe(gray, out);
  }
  DescriptorType descriptorType() const override { return DescriptorType::kSwif; }

 private:
  Swif swif_;
};

class SiftDetector final : public FeatureDetector {
 public:
  explicit SiftDetector(const DetectorOptions& o)
      : sift_(cv::SIFT::create(o.sift_max_features, o.sift_octave_layers, o.sift_contrast_threshold,
                               o.sift_edge_threshold, o.sift_sigma, CV_8U)) {}
  Status detect(const cv::Mat& gray, Features* out) override {
    if (Status s = checkImage(gray); !s.ok()) return s;
    out->type = DescriptorType::kSift;
    out->keypoints.clear();
    sift_->detectAndCompute(gray, cv::noArray(), out->keypoints, out->descriptors);
    return Status::Ok();
  }
  DescriptorType descriptorType() const override { return DescriptorType::kSift; }

 private:
  cv::Ptr<cv::SIFT> sift_;
};

class OrbDetector final : public FeatureDetector {
 public:
  explicit OrbDetector(const DetectorOptions& o)
      : o_(o),
        orb_(cv::ORB::create(o.orb_grid_cols > 0 ? 3 * o.orb_max_features : o.orb_max_features,
                             static_cast<float>(o.orb_scale_factor), o.orb_levels, 31, 0, 2,
                             cv::ORB::HARRIS_SCORE, 31, o.orb_fast_threshold)) {}
  Status detect(const cv::Mat& gray, Features* out) override {
    if (Status s = checkImage(gray); !s.ok()) return s;
    out->type = DescriptorType::kOrb;
    out->keypoints.clear();
    if (o_.orb_grid_cols > 0) {
      // Over-detect, spread over a grid, then describe only the kept keypoints.
      std::vector<cv::KeyPoint> all;
      orb_->detect(gray, all);
      out->keypoints =
          retainUniform(all, gray.size(), o_.orb_max_features, o_.orb_grid_cols, o_.orb_grid_rows);
      orb_->compute(gray, out->keypoints, out->descriptors);
    } else {
      orb_->detectAndCompute(gray, cv::noArray(), out->keypoints, out->descriptors);
    }
    if (out->descriptors.empty()) out->descriptors = cv::Mat(0, 32, CV_8U);
    return Status::Ok();
  }
  DescriptorType descriptorType() const override { return DescriptorType::kOrb; }

 private:
  DetectorOptions o_;
  cv::Ptr<cv::ORB> orb_;
};

}  // namespace

Expected<std::unique_ptr<FeatureDetector>> makeFeatureDetector(const DetectorOptions& o) {
  std::unique_ptr<FeatureDetector> d;
  switch (o.type) {
    case DetectorType::kAdaptiveSift:
      d = std::make_unique<AdaptiveSiftDetector>(o.adaptive_sift);
      break;
    case DetectorType::kFastSift:
      d = std::make_unique<FastSiftDetector>(o);
      break;
    case DetectorType::kSift:
      d = std::make_unique<SiftDetector>(o);
      break;
    case DetectorType::kOrb:
      d = std::make_unique<OrbDetector>(o);
      break;
    case DetectorType::kSwif:
      d = std::make_unique<SwifDetector>(o.swif);
      break;
  }
  if (!d) return Status::Error("feature detector: unknown type");
  return Expected<std::unique_ptr<FeatureDetector>>(std::move(d));
}

}  // namespace cvslam::vision
