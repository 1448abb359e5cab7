// cvslam_detector_eval — SWIF (thesis §4.4) against adaptive SIFT and ORB in the thesis's terms:
// repeatability (§4.4.5–4.4.6), good matches / precision / matching score (§4.4.7.2) and the
// computation time per image (§4.4.8), on rendered ground images with a known homography and on
// the real EuRoC frames of a euroc_micro-like folder (consecutive left frames, checked by a
// RANSAC fundamental matrix; rectified left/right pairs, checked by the epipolar constraint).
// A thin shell: the detectors and the metrics live in common/vision, the views in common/render.

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "cvslam/camera/euroc_calibration.h"
#include "cvslam/io/cli.h"
#include "cvslam/io/config_node.h"
#include "cvslam/render/view_changes.h"
#include "cvslam/vision/detector_eval.h"
#include "cvslam/vision/feature_detector.h"
#include "cvslam/vision/stereo_rectifier.h"

namespace {

using namespace cvslam;

constexpr const char* kUsage =
    R"(cvslam_detector_eval — compares feature detectors/descriptors (SWIF, thesis §4.4)

Usage: cvslam_detector_eval [options]
  --detectors LIST       comma-separated: swif, swif_thesis, adaptive_sift, fast_sift,
                         sift, orb (default swif,adaptive_sift,orb). swif_thesis is SWIF
                         with every step read literally from the thesis (response
                         directions, scale_axis orders, orders 2,4,6,8, descriptor
                         histogram; docs/front_end.md "SWIF")
  --config FILE          front-end YAML; detector options from front_end.detector (the
                         type is overridden per detector)
  --euroc DIR            EuRoC ASL folder (the one holding cam0/, cam1/) for the real-frame
                         tables; without it only the rendered tables are printed
  --frames N             real frames used (consecutive pairs and stereo pairs; default 20)
  --stride N             frames between the two images of a consecutive pair (default 1)
  --eps PX               repeatability / correct-match tolerance [px] (default 2.5)
  --seed N               seed of the rendered world (default 1)
  --dist-ratio R         matcher DistRatio (§4.2.6, default 0.8; L2, mutual)
  -h, --help             this text
)";

int fail(const std::string& message) {
  std::cerr << "cvslam_detector_eval: " << message << '\n';
  return 2;
}

constexpr int kGroundSide = 1024;  // rendering from which the 640 × 480 views are cut
const cv::Size kViewSize(640, 480);
constexpr double kGroundFocal = 0.6 * kGroundSide;  // as renderGroundImage
constexpr double kStereoMaxDisparity = 150.0;       // ≥ f·b/z_min for EuRoC (458·0.11/0.4)

struct Accumulator {  // sums over the pairs of one row
  int pairs = 0;
  double features = 0, repeatability = 0, matches = 0, correct = 0, precision = 0, score = 0;
  bool has_repeatability = false;
  void add(const vision::MatchQuality& q, double features_per_image) {
    ++pairs;
    features += features_per_image;
    matches += q.matches;
    correct += q.correct;
    precision += q.precision;
    score += q.matching_score;
  }
};

struct Timer {
  double total_ms = 0;
  int images = 0;
};

Status detect(vision::FeatureDetector& d, const cv::Mat& img, vision::Features* f, Timer* t) {
  const auto t0 = std::chrono::steady_clock::now();
  Status s = d.detect(img, f);
  t->total_ms +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ++t->images;
  return s;
}

std::string fixed(double v, int digits) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(digits) << v;
  return os.str();
}

void printRow(const std::string& det, const std::string& what, const Accumulator& a) {
  const double n = a.pairs > 0 ? a.pairs : 1;
  std::cout << "| " << det << " | " << what << " | " << fixed(a.features / n, 0) << " | "
            << (a.has_repeatability ? fixed(100.0 * a.repeatability / n, 1) : std::string("–"))
            << " | " << fixed(a.matches / n, 1) << " | " << fixed(a.correct / n, 1) << " | "
            << fixed(100.0 * a.precision / n, 1) << " | " << fixed(100.0 * a.score / n, 1)
            << " |\n";
}

void printHeader(const std::string& title) {
  std::cout << "\n### " << title << "\n\n"
            << "| detector | change | features/image | repeatability % | matches | good "
               "matches (NGM) | precision % | matching score % |\n"
            << "|---|---|---:|---:|---:|---:|---:|---:|\n";
}

std::vector<std::string> stamps(const std::string& csv) {
  std::vector<std::string> out;
  std::ifstream is(csv);
  std::string line;
  while (std::getline(is, line)) {
    if (line.empty() || line[0] == '#') continue;
    out.push_back(line.substr(0, line.find(',')));
  }
  return out;
}

vision::DetectorOptions optionsFor(const std::string& name, vision::DetectorType type,
                                   const vision::DetectorOptions& base) {
  vision::DetectorOptions o = base;
  o.type = type;
  if (name == "swif_thesis") {
    o.swif.response = vision::SwifResponse::kDirections;
    o.swif.scale_axis = vision::SwifScaleAxis::kOrders;
    o.swif.orders = {2, 4, 6, 8};
    o.swif.descriptor = vision::SwifDescriptorLayout::kHistogram;
  }
  return o;
}

vision::CameraCalibration toVision(const EurocCameraCalibration& c) {
  vision::CameraCalibration v;
  v.width = c.width;
  v.height = c.height;
  v.fx = c.intrinsics[0];
  v.fy = c.intrinsics[1];
  v.cx = c.intrinsics[2];
  v.cy = c.intrinsics[3];
  v.distortion = {c.distortion[0], c.distortion[1], c.distortion[2], c.distortion[3]};
  v.T_CtoB.matrix() = c.T_CtoB;
  return v;
}

struct EvalContext {
  std::vector<std::string> names;
  std::map<std::string, vision::DetectorType> types;
  vision::DetectorOptions base;
  vision::MatchOptions match;
  double eps = 2.5;
};

/// The rendered view changes: per detector and change, and the mean per family.
Status evaluateRendered(const EvalContext& c, const std::vector<render::ViewPair>& views,
                        std::map<std::string, Timer>* time) {
  for (const auto& name : c.names) {
    const vision::DetectorOptions o = optionsFor(name, c.types.at(name), c.base);
    auto det = vision::makeFeatureDetector(o);
    if (!det.ok()) return Status::Error(det.status().message());
    std::map<std::string, Accumulator> by_family;
    std::vector<std::string> order;
    for (const auto& v : views) {
      vision::Features a, b;
      if (Status s = detect(**det, v.reference, &a, &(*time)[name]); !s.ok())
        return Status::Error(s.message());
      if (Status s = detect(**det, v.transformed, &b, &(*time)[name]); !s.ok())
        return Status::Error(s.message());
      const auto rep =
          vision::repeatability(a.keypoints, kViewSize, b.keypoints, kViewSize, v.change.H, c.eps);
      const auto m = vision::matchDescriptors(a, b, c.match);
      const auto q = vision::matchQualityHomography(a, b, m, v.change.H, c.eps);
      std::ostringstream label;
      label << v.change.family << ' '
            << (v.change.family == "illumination" && v.change.gamma != 1.0
                    ? "γ " + fixed(v.change.gamma, 1)
                    : fixed(
                          v.change.amount,
                          v.change.family == "rotation" || v.change.family == "viewpoint" ? 0 : 2));
      Accumulator acc;
      acc.add(q, 0.5 * static_cast<double>(a.size() + b.size()));
      acc.has_repeatability = true;
      acc.repeatability = rep.repeatability;
      printRow(name, label.str(), acc);
      Accumulator& f = by_family[v.change.family];
      if (!f.pairs) order.push_back(v.change.family);
      f.add(q, 0.5 * static_cast<double>(a.size() + b.size()));
      f.has_repeatability = true;
      f.repeatability += rep.repeatability;
    }
    for (const auto& fam : order) printRow(name, "**mean " + fam + "**", by_family[fam]);
  }
  return Status::Ok();
}

/// The real EuRoC frames: consecutive left frames (RANSAC F) and rectified stereo pairs.
Status evaluateReal(const EvalContext& c, const std::string& euroc_dir,
                    const std::vector<std::string>& real, const vision::StereoRectifier& rectifier,
                    int frames, int stride, std::map<std::string, Timer>* time) {
  const int n = std::min(frames, static_cast<int>(real.size()) - stride);
  printHeader("Real EuRoC frames: " + std::to_string(n) + " consecutive left pairs (stride " +
              std::to_string(stride) + "; good = RANSAC-F inlier at eps) and " + std::to_string(n) +
              " rectified stereo pairs (good = |Δv| ≤ eps, 0 < d ≤ " +
              fixed(kStereoMaxDisparity, 0) + ")");
  for (const auto& name : c.names) {
    const vision::DetectorOptions o = optionsFor(name, c.types.at(name), c.base);
    auto det = vision::makeFeatureDetector(o);
    if (!det.ok()) return Status::Error(det.status().message());
    Accumulator temporal, stereo;
    for (int i = 0; i < n; ++i) {
      const std::string dir = euroc_dir + "/cam0/data/";
      const cv::Mat l0 =
          cv::imread(dir + real[static_cast<std::size_t>(i)] + ".png", cv::IMREAD_GRAYSCALE);
      const cv::Mat l1 = cv::imread(dir + real[static_cast<std::size_t>(i + stride)] + ".png",
                                    cv::IMREAD_GRAYSCALE);
      const cv::Mat r0 =
          cv::imread(euroc_dir + "/cam1/data/" + real[static_cast<std::size_t>(i)] + ".png",
                     cv::IMREAD_GRAYSCALE);
      if (l0.empty() || l1.empty() || r0.empty())
        return Status::Error("cannot read frame " + real[static_cast<std::size_t>(i)]);
      vision::Features a, b;
      if (Status s = detect(**det, l0, &a, &(*time)[name]); !s.ok())
        return Status::Error(s.message());
      if (Status s = detect(**det, l1, &b, &(*time)[name]); !s.ok())
        return Status::Error(s.message());
      const auto m = vision::matchDescriptors(a, b, c.match);
      temporal.add(vision::matchQualityFundamental(a, b, m, c.eps),
                   0.5 * static_cast<double>(a.size() + b.size()));
      cv::Mat lr, rr;
      if (Status s = rectifier.rectify(l0, r0, &lr, &rr); !s.ok())
        return Status::Error(s.message());
      vision::Features sl, sr;
      if (Status s = detect(**det, lr, &sl, &(*time)[name]); !s.ok())
        return Status::Error(s.message());
      if (Status s = detect(**det, rr, &sr, &(*time)[name]); !s.ok())
        return Status::Error(s.message());
      const auto ms = vision::matchDescriptors(sl, sr, c.match);
      stereo.add(vision::matchQualityStereo(sl, sr, ms, c.eps, 0.0, kStereoMaxDisparity),
                 0.5 * static_cast<double>(sl.size() + sr.size()));
    }
    printRow(name, "consecutive left frames", temporal);
    printRow(name, "stereo left/right", stereo);
  }
  return Status::Ok();
}

}  // namespace

int main(int argc, char** argv) {
  std::string detectors_arg = "swif,adaptive_sift,orb", config_path, euroc_dir;
  int frames = 20, stride = 1, seed = 1;
  double eps = 2.5, dist_ratio = 0.8;
  CLI::App app("compares feature detectors", "cvslam_detector_eval");
  app.add_option("--detectors", detectors_arg);
  app.add_option("--config", config_path);
  app.add_option("--euroc", euroc_dir);
  app.add_option("--frames", frames)->check(cli::kPositive);
  app.add_option("--stride", stride)->check(cli::kPositive);
  app.add_option("--eps", eps)->check(cli::kPositive);
  app.add_option("--seed", seed)->check(cli::kNonNegative);
  app.add_option("--dist-ratio", dist_ratio)
      ->check(cli::numberValidator("RATIO", "a number in (0, 1]",
                                   [](double x) { return x > 0.0 && x <= 1.0; }));
  if (auto exit_code = cli::parse(app, argc, argv, kUsage)) return *exit_code;

  vision::DetectorOptions base;
  if (!config_path.empty()) {
    auto cfg = ConfigNode::loadFile(config_path);
    if (!cfg.ok()) return fail(cfg.status().message());
    if (Status s = base.load(cfg->child("front_end").child("detector")); !s.ok())
      return fail(s.message());
  }
  const std::map<std::string, vision::DetectorType> kTypes = {
      {"swif", vision::DetectorType::kSwif},
      {"swif_thesis", vision::DetectorType::kSwif},
      {"adaptive_sift", vision::DetectorType::kAdaptiveSift},
      {"fast_sift", vision::DetectorType::kFastSift},
      {"sift", vision::DetectorType::kSift},
      {"orb", vision::DetectorType::kOrb}};
  std::vector<std::string> names;
  {
    std::stringstream ss(detectors_arg);
    std::string n;
    while (std::getline(ss, n, ','))
      if (!n.empty()) {
        if (!kTypes.count(n)) return fail("unknown detector '" + n + "' (--detectors)");
        names.push_back(n);
      }
    if (names.empty()) return fail("--detectors lists no detector");
  }
  vision::MatchOptions match;
  match.norm = vision::MatchNorm::kL2;  // Hamming for ORB (effectiveNorm)
  match.dist_ratio = dist_ratio;
  match.mutual = true;

  // Real data first checked, so that a bad folder fails before minutes of work.
  std::vector<std::string> real;
  std::optional<vision::StereoRectifier> rectifier;
  if (!euroc_dir.empty()) {
    if (!std::filesystem::is_directory(euroc_dir + "/cam0/data"))
      return fail("--euroc " + euroc_dir + ": no cam0/data folder (expected an EuRoC mav0 folder)");
    const auto left = stamps(euroc_dir + "/cam0/data.csv");
    const auto right = stamps(euroc_dir + "/cam1/data.csv");
    const std::set<std::string> r(right.begin(), right.end());
    for (const auto& s : left)
      if (r.count(s)) real.push_back(s);
    if (static_cast<int>(real.size()) < stride + 1)
      return fail("--euroc " + euroc_dir + ": fewer stereo frames than --stride + 1");
    auto calib = loadEurocStereoCalibration(euroc_dir);
    if (!calib.ok()) return fail(calib.status().message());
    auto rect = vision::StereoRectifier::create({toVision(calib->left), toVision(calib->right)});
    if (!rect.ok()) return fail(rect.status().message());
    rectifier.emplace(std::move(*rect));
  }

  auto ground = render::renderGroundImage(kGroundSide, static_cast<uint64_t>(seed));
  if (!ground.ok()) return fail(ground.status().message());
  std::vector<render::ViewChange> changes;
  for (double deg : {15.0, 45.0, 90.0}) changes.push_back(render::rotationChange(deg, kViewSize));
  for (double s : {1.25, 1.5, 2.0}) changes.push_back(render::scaleChange(s, kViewSize));
  for (double deg : {20.0, 40.0})
    changes.push_back(render::viewpointChange(deg, kViewSize, kGroundFocal));
  for (double sigma : {1.0, 2.0, 3.0}) changes.push_back(render::blurChange(sigma));
  changes.push_back(render::illuminationChange(0.5, 1.0));
  changes.push_back(render::illuminationChange(1.0, 1.8));
  std::vector<render::ViewPair> views;
  for (const auto& c : changes) views.push_back(render::makeViewPair(*ground, kViewSize, c));

  std::map<std::string, Timer> rendered_time, real_time;
  std::cout << "# cvslam_detector_eval: eps " << eps << " px, DistRatio " << dist_ratio
            << ", mutual, L2 (ORB: Hamming)\n";
  printHeader("Rendered ground image (640×480 views of a 1024² nadir rendering, known homography)");
  const EvalContext context{names, kTypes, base, match, eps};
  if (Status s = evaluateRendered(context, views, &rendered_time); !s.ok())
    return fail(s.message());

  if (rectifier) {
    if (Status s = evaluateReal(context, euroc_dir, real, *rectifier, frames, stride, &real_time);
        !s.ok())
      return fail(s.message());
  }

  std::cout
      << "\n### Computation time per image (detector + descriptor, this machine, 1 thread)\n\n"
      << "| detector | rendered 640×480 [ms] | real 752×480 [ms] |\n|---|---:|---:|\n";
  for (const auto& name : names) {
    const Timer& r = rendered_time[name];
    const Timer& e = real_time[name];
    std::cout << "| " << name << " | " << fixed(r.images ? r.total_ms / r.images : 0.0, 1) << " | "
              << (e.images ? fixed(e.total_ms / e.images, 1) : std::string("–")) << " |\n";
  }
  return 0;
}
