#include "cvslam/vision/stereo_front_end.h"

#include <algorithm>

#include "cvslam/io/config_node.h"

namespace cvslam::vision {

Status StereoFrontEndOptions::load(const ConfigNode& node) {
  detector.load(node.child("detector"));
  stereo.load(node.child("stereo"));
  row_search.load(node.child("row_search"));
  node.get("max_observations", max_observations);
  node.check(max_observations >= 0, "max_observations", "must be >= 0");
  return node.status();
}

Expected<StereoFrontEnd> StereoFrontEnd::create(const StereoFrontEndOptions& options,
                                                std::shared_ptr<const Vocabulary> vocabulary) {
  if (Status s = options.stereo.check(); !s.ok()) return s;
  auto detector = makeFeatureDetector(options.detector);
  if (!detector.ok()) return detector.status();
  if (vocabulary && vocabulary->type() != (*detector)->descriptorType())
    return Status::Error("front end: the vocabulary's descriptor type differs from the detector's");
  StereoFrontEnd fe;
  fe.o_ = options;
  if (options.detector.type == DetectorType::kFastSift) {
    fe.fast_sift_ =
        std::make_shared<FastSift>(options.detector.adaptive_sift, options.detector.fast_sift);
    fe.row_search_ = std::make_shared<RowStereoSearch>();
  }
  fe.detector_ = std::move(detector.value());
  fe.vocabulary_ = std::move(vocabulary);
  return fe;
}

Status StereoFrontEnd::matchDescribed(const cv::Mat& left, const cv::Mat& right) {
  if (Status s = detector_->detect(left, &frame_.left); !s.ok()) return s;
  if (Status s = detector_->detect(right, &frame_.right); !s.ok()) return s;
  frame_.left_detected = frame_.left.size();
  frame_.matches = matchStereo(frame_.left, frame_.right, o_.stereo);
  return Status::Ok();
}

// Left keypoints only; the right image is searched along the row (§4.2.8 window) and only the
// matched keypoints get an orientation and a descriptor. The match distance is 1 − ZNCC.
Status StereoFrontEnd::matchAlongRows(const cv::Mat& left, const cv::Mat& right) {
  std::vector<cv::KeyPoint>& detected = detected_;
  if (Status s = fast_sift_->detect(left, &detected); !s.ok()) return s;
  if (right.type() != CV_8UC1) return Status::Error("front end: expected 8-bit grey images");
  frame_.left_detected = detected.size();
  row_search_->search(left, right, detected, o_.stereo, o_.row_search, &row_matches_);
  // max_observations applies before the descriptors are computed: the rest are not described.
  if (o_.max_observations > 0 && static_cast<int>(row_matches_.size()) > o_.max_observations) {
    std::stable_sort(
        row_matches_.begin(), row_matches_.end(),
        [](const RowStereoMatch& a, const RowStereoMatch& b) { return a.score > b.score; });
    row_matches_.resize(static_cast<std::size_t>(o_.max_observations));
    std::sort(row_matches_.begin(), row_matches_.end(),
              [](const RowStereoMatch& a, const RowStereoMatch& b) { return a.left < b.left; });
  }
  frame_.left.type = DescriptorType::kSift;
  frame_.right.type = DescriptorType::kSift;
  frame_.left.keypoints.clear();
  frame_.matches.clear();
  std::vector<cv::KeyPoint> right_points;
  right_points.reserve(row_matches_.size());
  for (const RowStereoMatch& rm : row_matches_) {
    const cv::KeyPoint& kl = detected[static_cast<std::size_t>(rm.left)];
    const int index = static_cast<int>(frame_.left.keypoints.size());
    frame_.left.keypoints.push_back(kl);
    cv::KeyPoint kr = kl;
    kr.pt = rm.right;
    kr.response = static_cast<float>(rm.score);
    right_points.push_back(kr);
    frame_.matches.push_back({index, index, 1.0 - rm.score});
  }
  frame_.right.keypoints = std::move(right_points);
  frame_.right.descriptors = cv::Mat(0, descriptorBytes(DescriptorType::kSift), CV_8U);
  fast_sift_->describe(&frame_.left.keypoints, &frame_.left.descriptors);
  for (std::size_t i = 0; i < frame_.left.size(); ++i)
    frame_.right.keypoints[i].angle = frame_.left.keypoints[i].angle;
  return Status::Ok();
}

Status StereoFrontEnd::process(const cv::Mat& left, const cv::Mat& right,
                               std::vector<StereoObservation>* observations) {
  observations->clear();
  if (left.size() != right.size())
    return Status::Error("front end: left and right images differ in size");
  const Status matched = fast_sift_ ? matchAlongRows(left, right) : matchDescribed(left, right);
  if (!matched.ok()) return matched;
  std::vector<StereoMatch>& m = frame_.matches;
  if (o_.max_observations > 0 && static_cast<int>(m.size()) > o_.max_observations) {
    std::stable_sort(m.begin(), m.end(), [](const StereoMatch& a, const StereoMatch& b) {
      return a.distance < b.distance;
    });
    m.resize(static_cast<std::size_t>(o_.max_observations));
  }
  const int bytes = descriptorBytes(frame_.left.type);
  observations->reserve(m.size());
  for (const StereoMatch& sm : m) {
    const cv::KeyPoint& kl = frame_.left.keypoints[static_cast<std::size_t>(sm.left)];
    const cv::KeyPoint& kr = frame_.right.keypoints[static_cast<std::size_t>(sm.right)];
    StereoObservation obs;
    obs.z = Eigen::Vector4d(kl.pt.x, kl.pt.y, kr.pt.x, kr.pt.y);
    const uint8_t* d = frame_.left.descriptor(static_cast<std::size_t>(sm.left));
    obs.descriptor.assign(d, d + bytes);
    obs.index = vocabulary_ ? vocabulary_->word(d) : 0u;
    obs.type = ObservationType::kNew;
    obs.landmark_id = -1;
    observations->push_back(std::move(obs));
  }
  return Status::Ok();
}

}  // namespace cvslam::vision
