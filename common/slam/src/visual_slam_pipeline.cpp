#include "cvslam/slam/visual_slam_pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <type_traits>

#include <Eigen/Eigenvalues>

#include "cvslam/io/config_node.h"

namespace cvslam {

namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// SIFT gives one keypoint per dominant orientation, so one image point can come as several
/// observations with different descriptors. The filter must see each point once (twice would
/// count its information twice and make the estimate over-confident): of the observations
/// sharing a left pixel, the one associated to the oldest landmark stays, else the first.
/// Returns how many were removed.
int removeDuplicatePoints(std::vector<StereoObservation>* observations) {
  std::vector<StereoObservation>& obs = *observations;
  std::vector<std::size_t> order(obs.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  auto pixel_less = [&](std::size_t a, std::size_t b) {
    return obs[a].z(0) < obs[b].z(0) || (obs[a].z(0) == obs[b].z(0) && obs[a].z(1) < obs[b].z(1));
  };
  std::stable_sort(order.begin(), order.end(), pixel_less);
  std::vector<bool> drop(obs.size(), false);
  int removed = 0;
  for (std::size_t g = 0; g < order.size();) {
    std::size_t end = g + 1;
    while (end < order.size() && !pixel_less(order[g], order[end])) ++end;
    std::size_t keep = order[g];
    for (std::size_t k = g; k < end; ++k) {
      const StereoObservation& o = obs[order[k]];
      const StereoObservation& best = obs[keep];
      if (o.landmark_id >= 0 && (best.landmark_id < 0 || o.landmark_id < best.landmark_id)) {
        keep = order[k];
      } else if (o.landmark_id < 0 && best.landmark_id < 0 && order[k] < keep) {
        keep = order[k];
      }
    }
    for (std::size_t k = g; k < end; ++k) {
      if (order[k] != keep) {
        drop[order[k]] = true;
        ++removed;
      }
    }
    g = end;
  }
  std::size_t out = 0;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    if (drop[i]) continue;
    if (out != i) obs[out] = std::move(obs[i]);
    ++out;
  }
  obs.resize(out);
  return removed;
}

/// A new point confirmed frame to frame, for the offer to the filter.
struct ConfirmedPoint {
  double rank;  ///< smaller is offered first: the confirmation residual (max |z − ẑ|, px)
  std::size_t obs;
};

/// new_landmark_order: response. The strongest point of every grid cell first, then the second
/// strongest of every cell, …: the scene's most distinctive points, spread over the view.
void rankByResponse(const std::vector<StereoObservation>& observations, int grid,
                    const StereoCameraOptions& camera, std::vector<ConfirmedPoint>* found) {
  std::sort(found->begin(), found->end(), [&](const ConfirmedPoint& p, const ConfirmedPoint& q) {
    const float rp = observations[p.obs].response, rq = observations[q.obs].response;
    return rp > rq || (rp == rq && p.obs < q.obs);
  });
  std::vector<int> taken(static_cast<std::size_t>(grid * grid), 0);
  for (std::size_t k = 0; k < found->size(); ++k) {
    const Eigen::Vector4d& z = observations[(*found)[k].obs].z;
    const int cx = std::clamp(static_cast<int>(z(0) * grid / camera.width), 0, grid - 1);
    const int cy = std::clamp(static_cast<int>(z(1) * grid / camera.height), 0, grid - 1);
    // Round in the cell, then position in the strength order.
    (*found)[k].rank = static_cast<double>(taken[static_cast<std::size_t>(cy * grid + cx)]++) *
                           static_cast<double>(found->size()) +
                       static_cast<double>(k);
  }
}

}  // namespace

Status VisualFrontEndOptions::load(const ConfigNode& node) {
  front_end.load(node);
  association.load(node.child("association"));
  prediction.load(node.child("prediction"));
  node.get("max_hamming_distance", max_hamming_distance);
  node.get("vocabulary", vocabulary);
  node.get("vocabulary_orb", vocabulary_orb);
  loop_detection.load(node.child("loop_detection"));
  node.get("confirm_new", confirm_new);
  node.get("confirm_gate_px", confirm_gate_px);
  node.get("tracked_landmarks", tracked_landmarks);
  node.get("drop_duplicate_points", drop_duplicate_points);
  node.getEnum("new_landmark_order", new_landmark_order,
               {{"response", NewLandmarkOrder::kResponse},
                {"confirmation", NewLandmarkOrder::kConfirmation}});
  node.get("new_landmark_grid", new_landmark_grid);
  node.check(new_landmark_grid >= 1 && new_landmark_grid <= 64, "new_landmark_grid",
             "must be in [1, 64]");
  // Overrides of slam options: set only when the key is present.
  auto override = [&node](const char* key, auto* out) {
    if (!node.has(key)) return;
    typename std::decay_t<decltype(*out)>::value_type value{};
    node.get(key, value);
    *out = value;
  };
  override("first_estimate_jacobians", &first_estimate_jacobians);
  override("observability_constrained", &observability_constrained);
  override("second_order_noise", &second_order_noise);
  override("second_order_mean", &second_order_mean);
  override("pixel_sigma", &pixel_sigma);
  if (pixel_sigma) node.check(*pixel_sigma > 0.0, "pixel_sigma", "must be > 0");
  node.check(confirm_gate_px > 0.0, "confirm_gate_px", "must be > 0");
  node.check(tracked_landmarks >= 0, "tracked_landmarks", "must be ≥ 0");
  node.check(max_hamming_distance > 0.0, "max_hamming_distance", "must be > 0");
  return node.status();
}

Expected<std::shared_ptr<const vision::Vocabulary>> loadFeatureIndexVocabulary(
    const VisualFrontEndOptions& options, const std::string& config_dir) {
  const bool orb = options.front_end.detector.type == vision::DetectorType::kOrb;
  // SWIF descriptors (thesis §4.4) have no trained vocabulary: the feature index is off for
  // them (a SIFT vocabulary would read 128 bytes of 64-byte descriptors).
  if (options.front_end.detector.type == vision::DetectorType::kSwif)
    return std::shared_ptr<const vision::Vocabulary>();
  const std::string& name = orb ? options.vocabulary_orb : options.vocabulary;
  if (name.empty()) return std::shared_ptr<const vision::Vocabulary>();
  std::filesystem::path file = name;
  if (file.is_relative()) file = std::filesystem::path(config_dir) / file;
  auto v = vision::Vocabulary::load(file.string());
  if (!v.ok()) return v.status();
  const vision::DescriptorType wanted =
      orb ? vision::DescriptorType::kOrb : vision::DescriptorType::kSift;
  if (v->type() != wanted) {
    return Status::Error(file.string() + ": vocabulary of " +
                         (v->type() == vision::DescriptorType::kOrb ? "ORB" : "SIFT") +
                         " descriptors does not fit the " + (orb ? "ORB" : "SIFT") +
                         " detector (frontend." + (orb ? "vocabulary_orb" : "vocabulary") + ")");
  }
  return std::make_shared<const vision::Vocabulary>(std::move(v.value()));
}

SlamOptions VisualFrontEndOptions::resolve(SlamOptions slam) const {
  slam.first_estimate_jacobians = first_estimate_jacobians.value_or(slam.first_estimate_jacobians);
  slam.observability_constrained =
      observability_constrained.value_or(slam.observability_constrained);
  slam.second_order_noise = second_order_noise.value_or(slam.second_order_noise);
  slam.second_order_mean = second_order_mean.value_or(slam.second_order_mean);
  slam.pixel_sigma = pixel_sigma.value_or(slam.pixel_sigma);
  return slam;
}

Expected<VisualSlamPipeline> VisualSlamPipeline::create(
    const VisualFrontEndOptions& options, const StereoCamera& camera,
    std::shared_ptr<const vision::Vocabulary> vocabulary) {
  VisualFrontEndOptions o = options;
  const StereoCameraOptions& c = camera.options();
  o.front_end.stereo.focal_px = c.fx;
  o.front_end.stereo.baseline_m = c.baseline;
  const bool orb = o.front_end.detector.type == vision::DetectorType::kOrb;
  o.association.descriptor_type = vision::descriptorTypeOf(o.front_end.detector.type);
  if (orb) {
    o.association.max_descriptor_distance = o.max_hamming_distance;
    o.loop_detection.max_descriptor_distance = o.max_hamming_distance;
  }
  const bool feature_index = vocabulary != nullptr;
  auto fe = vision::StereoFrontEnd::create(o.front_end, std::move(vocabulary));
  if (!fe.ok()) return fe.status();
  return VisualSlamPipeline(std::move(o), std::move(fe.value()), feature_index);
}

Status VisualSlamPipeline::process(int64_t t_us, const cv::Mat& left, const cv::Mat& right,
                                   VisualInertialSlam& slam, VisualFrameResult* result) {
  VisualFrameResult& r = *result;
  r = VisualFrameResult();
  // The image path's overrides of the measurement model, once, before its first frame.
  if (!measurement_model_set_) {
    slam.setMeasurementModel(o_.resolve(slam.options().slam));
    measurement_model_set_ = true;
  }
  r.frame.t_us = t_us;
  if (left.empty() || right.empty()) return Status::Error("pipeline: empty image");
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1) {
    return Status::Error("pipeline: images must be 8-bit grey (CV_8UC1)");
  }
  const StereoCameraOptions& c = slam.camera().options();
  if (left.cols != c.width || left.rows != c.height) {
    return Status::Error("pipeline: image size " + std::to_string(left.cols) + "×" +
                         std::to_string(left.rows) + " differs from the camera's " +
                         std::to_string(c.width) + "×" + std::to_string(c.height));
  }

  // 1. The filter propagated to the frame (the recipe's first step: its update then finds it
  // there), and the map's observations predicted at that time. They come first so that the
  // front end, when it keeps only max_observations, keeps the keypoints the association and
  // the confirmation will look for.
  auto t0 = std::chrono::steady_clock::now();
  if (Status s = slam.propagateTo(t_us); !s.ok()) return s;
  if (Status s = predictMapObservations(slam, o_.prediction, &predicted_); !s.ok()) return s;
  gated_.clear();
  for (const PredictedObservation& p : predicted_) {
    if (p.descriptor == nullptr || p.descriptor->empty()) continue;
    gated_.push_back({p.landmark_id, p.z, p.S, *p.descriptor});
  }
  r.predictions = static_cast<int>(gated_.size());
  if (o_.confirm_new) expectPrevious(slam);
  if (front_end_.keptMatches() > 0) priorityRegions();
  double prediction_ms = msSince(t0);

  // 2. Front end: features of both images, stereo matches → observations (type 3).
  t0 = std::chrono::steady_clock::now();
  if (Status s = front_end_.process(left, right, &r.frame.observations, &priority_); !s.ok()) {
    return s;
  }
  r.front_end_ms = msSince(t0);
  r.front_end = front_end_.lastFrame().timings;
  r.prioritised = front_end_.lastFrame().prioritised;

  t0 = std::chrono::steady_clock::now();
  // 3. Association by descriptor and Mahalanobis gate (type 1), fresh ids for the rest.
  if (Status s =
          vision::associateToMap(gated_, o_.association, &r.frame.observations, &r.association);
      !s.ok()) {
    return s;
  }
  if (o_.loop_detection.enabled && feature_index_ &&
      frames_ % o_.loop_detection.every_n_frames == 0) {
    detectLoop(t_us, slam, &r);
  }
  ++frames_;
  if (o_.drop_duplicate_points) r.duplicates = removeDuplicatePoints(&r.frame.observations);
  if (o_.confirm_new) {
    confirmNew(slam, &r.frame.observations, &r.confirmed);
  } else {
    for (StereoObservation& obs : r.frame.observations) {
      if (obs.landmark_id < 0) obs.landmark_id = next_landmark_id_++;
    }
  }
  filter_frame_.t_us = t_us;
  filter_frame_.observations.clear();
  filter_index_.clear();
  for (std::size_t i = 0; i < r.frame.observations.size(); ++i) {
    if (r.frame.observations[i].landmark_id < 0) continue;
    filter_frame_.observations.push_back(r.frame.observations[i]);
    filter_index_.push_back(i);
  }
  r.association_ms = prediction_ms + msSince(t0);

  // 4. The filter; a fresh id that is now in the state was initialised by this frame.
  t0 = std::chrono::steady_clock::now();
  if (Status s = slam.processFrame(filter_frame_, &r.report); !s.ok()) return s;
  r.filter_ms = msSince(t0);
  for (std::size_t k = 0; k < filter_frame_.observations.size(); ++k) {
    const StereoObservation& obs = filter_frame_.observations[k];
    if (obs.type != ObservationType::kNew) continue;
    if (slam.state().has(VariableKey::landmark(static_cast<uint64_t>(obs.landmark_id)))) {
      r.initialised.emplace_back(filter_index_[k], obs.landmark_id);
    }
  }
  if (o_.confirm_new) rememberUnmapped(slam, r);
  return Status::Ok();
}

void VisualSlamPipeline::expectPrevious(const VisualInertialSlam& slam) {
  const StereoCamera& camera = slam.camera();
  const vehicle_model::Pose x = slam.vehiclePose();
  expected_.resize(previous_.size());
  ahead_.assign(previous_.size(), false);
  for (std::size_t j = 0; j < previous_.size(); ++j) {
    const Eigen::Vector3d p_C = camera.landmarkInCamera(x, previous_[j].p_LinN);
    if (p_C.z() <= camera.options().min_depth) continue;
    expected_[j] = camera.project(p_C);
    ahead_[j] = true;
  }
}

void VisualSlamPipeline::priorityRegions() {
  priority_.clear();
  // The association's gate on [u_L v_L] alone: |Δu| ≤ √(χ²·S_uu) holds for every z inside the
  // 4-D Mahalanobis gate.
  const double chi2 = o_.association.gate_chi2;
  for (const vision::LandmarkPrediction& p : gated_) {
    priority_.push_back({cv::Point2f(static_cast<float>(p.z(0)), static_cast<float>(p.z(1))),
                         cv::Point2f(static_cast<float>(std::sqrt(chi2 * p.S(0, 0))),
                                     static_cast<float>(std::sqrt(chi2 * p.S(1, 1))))});
  }
  if (!o_.confirm_new) return;
  // The previous frame's unmapped points where the filter's motion puts them (confirmNew).
  const auto gate = static_cast<float>(o_.confirm_gate_px);
  for (std::size_t j = 0; j < previous_.size(); ++j) {
    if (!ahead_[j]) continue;
    priority_.push_back(
        {cv::Point2f(static_cast<float>(expected_[j](0)), static_cast<float>(expected_[j](1))),
         cv::Point2f(gate, gate)});
  }
}

vision::MatchNorm VisualSlamPipeline::descriptorNorm() const {
  const vision::MapAssociationOptions& a = o_.association;
  if (a.descriptor_type == vision::DescriptorType::kOrb) return vision::MatchNorm::kHamming;
  return a.norm == vision::MatchNorm::kHamming ? vision::MatchNorm::kL2 : a.norm;
}

void VisualSlamPipeline::detectLoop(int64_t t_us, const VisualInertialSlam& slam,
                                    VisualFrameResult* result) {
  const SlamOptions& s = slam.options().slam;
  const auto min_seen_us = static_cast<int64_t>(s.loop_closure_min_age_s * 1e6);
  std::vector<StereoObservation>& observations = result->frame.observations;
  LoopQuery query;
  query.t_us = t_us;
  query.x_v = slam.vehiclePose();
  const Eigen::Matrix2d P_horizontal = slam.vehicleCovariance().topLeftCorner<2, 2>();
  query.position_sigma_m = std::sqrt(std::max(
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(P_horizontal).eigenvalues().maxCoeff(), 0.0));
  query.min_last_seen_age_s = s.loop_closure_min_age_s;
  query.min_archived_age_s = s.reactivation_min_age_s;
  query.norm = descriptorNorm();
  result->loop = loop_detector_.detect(observations, slam.camera(), slam.archive(), query);
  std::vector<bool> verified(observations.size(), false);
  if (result->loop.detected) {
    for (const auto& [i, id] : result->loop.matches) {
      observations[i].landmark_id = id;
      observations[i].type = ObservationType::kReobserved;
      verified[i] = true;
    }
  }
  // Gated associations to loop landmarks that the verification did not keep are undone: a
  // loop is closed only on verified matches.
  for (std::size_t i = 0; i < observations.size(); ++i) {
    StereoObservation& obs = observations[i];
    if (verified[i] || obs.landmark_id < 0) continue;
    const ArchivedLandmark* a = slam.archive().find(obs.landmark_id);
    if (a != nullptr && t_us - a->last_seen_us >= min_seen_us) {
      obs.landmark_id = -1;
      obs.type = ObservationType::kNew;
    }
  }
}

void VisualSlamPipeline::confirmNew(const VisualInertialSlam& slam,
                                    std::vector<StereoObservation>* observations, int* confirmed) {
  // Where the previous frame's unmapped points are expected now: expected_, ahead_.
  const vision::MapAssociationOptions& a = o_.association;
  const int bytes = vision::descriptorBytes(a.descriptor_type);
  const vision::MatchNorm norm = descriptorNorm();
  std::vector<bool> taken(previous_.size(), false);
  std::vector<ConfirmedPoint> found;
  for (std::size_t i = 0; i < observations->size(); ++i) {
    const StereoObservation& obs = (*observations)[i];
    if (obs.landmark_id >= 0) continue;
    if (static_cast<int>(obs.descriptor.size()) != bytes) continue;
    double d1 = std::numeric_limits<double>::infinity(), d2 = d1;
    std::size_t best = previous_.size();
    for (std::size_t j = 0; j < previous_.size(); ++j) {
      if (!ahead_[j] || taken[j]) continue;
      if (((obs.z - expected_[j]).cwiseAbs().array() > o_.confirm_gate_px).any()) continue;
      const double d = vision::descriptorDistance(norm, obs.descriptor.data(),
                                                  previous_[j].descriptor->data(), bytes);
      if (d < d1) {
        d2 = d1;
        d1 = d;
        best = j;
      } else if (d < d2) {
        d2 = d;
      }
    }
    if (best == previous_.size() || d1 > a.max_descriptor_distance) continue;
    if (d2 < std::numeric_limits<double>::infinity() && !(d1 < a.dist_ratio * d2)) continue;
    taken[best] = true;
    found.push_back({(obs.z - expected_[best]).cwiseAbs().maxCoeff(), i});
  }
  // Offer the filter only as many as it initialises, in new_landmark_order (the strongest or
  // the best confirmed first): its own choice, nearest first, would favour the matches whose
  // disparity error is positive (too near). And only as many as the map has room for besides
  // the landmarks it tracks now.
  const int target = o_.tracked_landmarks > 0 ? o_.tracked_landmarks : slam.options().map.k;
  int tracked = 0;
  for (const StereoObservation& obs : *observations) {
    if (obs.landmark_id >= 0 &&
        slam.state().has(VariableKey::landmark(static_cast<uint64_t>(obs.landmark_id)))) {
      ++tracked;
    }
  }
  const int room = std::clamp(target - tracked, 0, slam.options().slam.max_new_landmarks_per_frame);
  const auto n_offer = std::min(found.size(), static_cast<std::size_t>(room));
  if (o_.new_landmark_order == NewLandmarkOrder::kResponse)
    rankByResponse(*observations, o_.new_landmark_grid, slam.camera().options(), &found);
  std::partial_sort(found.begin(), found.begin() + static_cast<std::ptrdiff_t>(n_offer),
                    found.end(), [](const ConfirmedPoint& p, const ConfirmedPoint& q) {
                      return p.rank < q.rank || (p.rank == q.rank && p.obs < q.obs);
                    });
  for (std::size_t k = 0; k < n_offer; ++k) {
    (*observations)[found[k].obs].landmark_id = next_landmark_id_++;
  }
  *confirmed = static_cast<int>(found.size());
}

void VisualSlamPipeline::rememberUnmapped(const VisualInertialSlam& slam,
                                          const VisualFrameResult& result) {
  const vehicle_model::Pose x = slam.vehiclePose();
  previous_observations_.clear();
  for (const StereoObservation& obs : result.frame.observations) {
    if (obs.type == ObservationType::kReobserved) continue;
    if (obs.landmark_id >= 0 &&
        slam.state().has(VariableKey::landmark(static_cast<uint64_t>(obs.landmark_id)))) {
      continue;  // initialised now: the map predicts it from here on
    }
    previous_observations_.push_back(obs);
  }
  previous_.clear();
  previous_.reserve(previous_observations_.size());
  for (const StereoObservation& obs : previous_observations_) {
    Eigen::Vector3d p_LinN;
    if (!slam.camera().triangulate(obs.z, x, &p_LinN).ok()) continue;
    previous_.push_back({p_LinN, &obs.descriptor});
  }
}

}  // namespace cvslam
