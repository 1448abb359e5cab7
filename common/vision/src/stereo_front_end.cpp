#include "cvslam/vision/stereo_front_end.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "cvslam/io/config_node.h"

namespace cvslam::vision {

namespace {

constexpr int kMaskCell = 4;  // priority mask resolution [px]: regions are ≥ a few px wide

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

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

void StereoFrontEnd::markPriority(cv::Size image, const std::vector<PriorityRegion>* priority) {
  mask_cols_ = (image.width + kMaskCell - 1) / kMaskCell;
  mask_rows_ = (image.height + kMaskCell - 1) / kMaskCell;
  mask_.assign(static_cast<std::size_t>(mask_cols_) * static_cast<std::size_t>(mask_rows_), 0);
  if (priority == nullptr) return;
  for (const PriorityRegion& r : *priority) {
    if (!std::isfinite(r.center.x) || !std::isfinite(r.center.y)) continue;
    const auto cell = [](float v) { return static_cast<int>(std::floor(v / kMaskCell)); };
    const int c0 = std::max(cell(r.center.x - r.half_size.x), 0);
    const int c1 = std::min(cell(r.center.x + r.half_size.x), mask_cols_ - 1);
    const int r0 = std::max(cell(r.center.y - r.half_size.y), 0);
    const int r1 = std::min(cell(r.center.y + r.half_size.y), mask_rows_ - 1);
    for (int row = r0; row <= r1; ++row)
      for (int col = c0; col <= c1; ++col)
        mask_[static_cast<std::size_t>(row) * static_cast<std::size_t>(mask_cols_) +
              static_cast<std::size_t>(col)] = 1;
  }
}

bool StereoFrontEnd::prioritised(const cv::Point2f& p) const {
  const int col = static_cast<int>(p.x) / kMaskCell, row = static_cast<int>(p.y) / kMaskCell;
  if (col < 0 || row < 0 || col >= mask_cols_ || row >= mask_rows_) return false;
  return mask_[static_cast<std::size_t>(row) * static_cast<std::size_t>(mask_cols_) +
               static_cast<std::size_t>(col)] != 0;
}

int StereoFrontEnd::keptMatches() const {
  if (!fast_sift_) return o_.max_observations;
  const int budget = o_.detector.fast_sift.describe_budget;
  if (budget == 0) return o_.max_observations;
  return o_.max_observations == 0 ? budget : std::min(budget, o_.max_observations);
}

template <typename Better>
void StereoFrontEnd::rank(std::size_t n, const std::vector<cv::Point2f>& left_px, int cap,
                          Better better) {
  order_.resize(n);
  for (std::size_t i = 0; i < n; ++i) order_[i] = i;
  std::vector<uint8_t>& in_region = rank_in_region_;
  in_region.resize(n);
  for (std::size_t i = 0; i < n; ++i) in_region[i] = prioritised(left_px[i]) ? 1 : 0;
  std::stable_sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) {
    if (in_region[a] != in_region[b]) return in_region[a] > in_region[b];
    return better(a, b);
  });
  const std::size_t kept = std::min(n, static_cast<std::size_t>(cap));
  frame_.prioritised = 0;
  for (std::size_t k = 0; k < kept; ++k) frame_.prioritised += in_region[order_[k]];
  order_.resize(kept);
}

Status StereoFrontEnd::matchDescribed(const cv::Mat& left, const cv::Mat& right) {
  auto t0 = std::chrono::steady_clock::now();
  if (Status s = detector_->detect(left, &frame_.left); !s.ok()) return s;
  if (Status s = detector_->detect(right, &frame_.right); !s.ok()) return s;
  frame_.timings.detect_ms = msSince(t0);
  t0 = std::chrono::steady_clock::now();
  frame_.left_detected = frame_.left.size();
  frame_.matches = matchStereo(frame_.left, frame_.right, o_.stereo);
  std::vector<StereoMatch>& m = frame_.matches;
  if (o_.max_observations > 0 && static_cast<int>(m.size()) > o_.max_observations) {
    rank_px_.resize(m.size());
    for (std::size_t i = 0; i < m.size(); ++i)
      rank_px_[i] = frame_.left.keypoints[static_cast<std::size_t>(m[i].left)].pt;
    rank(m.size(), rank_px_, o_.max_observations,
         [&m](std::size_t a, std::size_t b) { return m[a].distance < m[b].distance; });
    std::vector<StereoMatch> kept;
    kept.reserve(order_.size());
    for (std::size_t i : order_) kept.push_back(m[i]);
    m = std::move(kept);
  }
  frame_.timings.stereo_ms = msSince(t0);
  return Status::Ok();
}

// Left keypoints only; the right image is searched along the row (§4.2.8 window) and only the
// kept matches get an orientation and a descriptor. The match distance is 1 − ZNCC.
Status StereoFrontEnd::matchAlongRows(const cv::Mat& left, const cv::Mat& right) {
  if (right.type() != CV_8UC1) return Status::Error("front end: expected 8-bit grey images");
  auto t0 = std::chrono::steady_clock::now();
  std::vector<cv::KeyPoint>& detected = detected_;
  if (Status s = fast_sift_->detect(left, &detected); !s.ok()) return s;
  frame_.timings.detect_ms = msSince(t0);
  t0 = std::chrono::steady_clock::now();
  frame_.left_detected = detected.size();
  row_search_->search(left, right, detected, o_.stereo, o_.row_search, &row_matches_);
  // max_observations applies before the descriptors are computed: the rest are not described.
  const int cap = keptMatches();
  if (cap > 0 && static_cast<int>(row_matches_.size()) > cap) {
    rank_px_.resize(row_matches_.size());
    for (std::size_t i = 0; i < row_matches_.size(); ++i)
      rank_px_[i] = detected[static_cast<std::size_t>(row_matches_[i].left)].pt;
    rank(row_matches_.size(), rank_px_, cap, [this](std::size_t a, std::size_t b) {
      return row_matches_[a].score > row_matches_[b].score;
    });
    std::sort(order_.begin(), order_.end());  // keypoint order, as without the cap
    std::size_t out = 0;
    for (std::size_t i : order_) row_matches_[out++] = row_matches_[i];
    row_matches_.resize(out);
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
  frame_.timings.stereo_ms = msSince(t0);
  t0 = std::chrono::steady_clock::now();
  fast_sift_->describe(&frame_.left.keypoints, &frame_.left.descriptors);
  for (std::size_t i = 0; i < frame_.left.size(); ++i)
    frame_.right.keypoints[i].angle = frame_.left.keypoints[i].angle;
  frame_.timings.describe_ms = msSince(t0);
  return Status::Ok();
}

Status StereoFrontEnd::process(const cv::Mat& left, const cv::Mat& right,
                               std::vector<StereoObservation>* observations,
                               const std::vector<PriorityRegion>* priority) {
  observations->clear();
  frame_.timings = FrontEndTimings();
  frame_.prioritised = 0;
  if (left.size() != right.size())
    return Status::Error("front end: left and right images differ in size");
  if (keptMatches() > 0) markPriority(left.size(), priority);
  const Status matched = fast_sift_ ? matchAlongRows(left, right) : matchDescribed(left, right);
  if (!matched.ok()) return matched;
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<StereoMatch>& m = frame_.matches;
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
    obs.response = kl.response;
    observations->push_back(std::move(obs));
  }
  frame_.timings.index_ms = msSince(t0);
  return Status::Ok();
}

}  // namespace cvslam::vision
