#include "cvslam/mosaic/geometric_registration.h"

#include "cvslam/io/config_node.h"

namespace cvslam::mosaic {

Status RegistrationOptions::load(const ConfigNode& node) {
  sift.load(node.child("sift"));
  match.load(node.child("match"));
  homography.load(node.child("homography"));
  node.get("search_radius_px", search_radius_px);
  node.check(search_radius_px > 0.0, "search_radius_px", "must be > 0");
  return node.status();
}

Expected<Registration> registerFeatures(const vision::Features& image,
                                        const vision::Features& reference,
                                        const RegistrationOptions& o,
                                        const std::optional<Eigen::Matrix3d>& prior) {
  std::vector<vision::Match> matches;
  if (prior) {
    std::vector<cv::Point2f> predicted;
    predicted.reserve(image.size());
    for (const cv::KeyPoint& k : image.keypoints) {
      const Eigen::Vector2d p = applyHomography(*prior, Eigen::Vector2d(k.pt.x, k.pt.y));
      predicted.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
    }
    const auto candidates = vision::candidatesNear(predicted, reference, o.search_radius_px);
    matches = vision::matchDescriptors(image, reference, o.match, &candidates);
  } else {
    matches = vision::matchDescriptors(image, reference, o.match);
  }
  std::vector<Eigen::Vector2d> src, dst;
  for (const vision::Match& m : matches) {
    const cv::Point2f& a = image.keypoints[static_cast<std::size_t>(m.query)].pt;
    const cv::Point2f& b = reference.keypoints[static_cast<std::size_t>(m.train)].pt;
    src.emplace_back(a.x, a.y);
    dst.emplace_back(b.x, b.y);
  }
  auto estimate = estimateHomography(src, dst, o.homography);
  if (!estimate.ok()) return estimate.status();
  Registration r;
  r.estimate = std::move(*estimate);
  r.matches = static_cast<int>(matches.size());
  r.src = std::move(src);
  r.dst = std::move(dst);
  return r;
}

Expected<Registration> registerImages(const cv::Mat& image, const cv::Mat& reference,
                                      const RegistrationOptions& o,
                                      const std::optional<Eigen::Matrix3d>& prior) {
  vision::Features a, b;
  if (Status s = vision::detectAdaptiveSift(image, o.sift, &a); !s.ok()) return s;
  if (Status s = vision::detectAdaptiveSift(reference, o.sift, &b); !s.ok()) return s;
  return registerFeatures(a, b, o, prior);
}

}  // namespace cvslam::mosaic
