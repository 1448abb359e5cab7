#include "cvslam/vision/stereo_front_end.h"

#include <algorithm>

#include "cvslam/io/config_node.h"

namespace cvslam::vision {

Status StereoFrontEndOptions::load(const ConfigNode& node) {
  detector.load(node.child("detector"));
  stereo.load(node.child("stereo"));
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
  fe.detector_ = std::move(detector.value());
  fe.vocabulary_ = std::move(vocabulary);
  return fe;
}

Status StereoFrontEnd::process(const cv::Mat& left, const cv::Mat& right,
                               std::vector<StereoObservation>* observations) {
  observations->clear();
  if (left.size() != right.size())
    return Status::Error("front end: left and right images differ in size");
  if (Status s = detector_->detect(left, &frame_.left); !s.ok()) return s;
  if (Status s = detector_->detect(right, &frame_.right); !s.ok()) return s;
  frame_.matches = matchStereo(frame_.left, frame_.right, o_.stereo);
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
