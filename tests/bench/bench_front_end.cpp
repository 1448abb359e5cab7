// Whole stereo front end per pair (detect + describe both images + stereo match + word ids),
// single thread, on the real rectified EuRoC V1_01 pair at 752×480 and a 320×240 version
// (half-size, centre crop). Targets (docs/front_end.md brief): ORB ≤ 15 ms / ≤ 40 ms.
//   ./build/tests/bench_front_end --benchmark_repetitions=3

#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "../core/vision_test_data.h"
#include "cvslam/vision/adaptive_sift.h"
#include "cvslam/vision/descriptor_matcher.h"
#include "cvslam/vision/stereo_front_end.h"
#include "cvslam/vision/stereo_rectifier.h"

namespace {

using namespace cvslam::vision;

struct Pair {
  cv::Mat left, right;
  double f = 0, baseline = 0;
};

// Rectified real pair; small = 320×240 (half resolution, centre crop).
Pair loadPair(bool small) {
  Pair p;
  StereoCalibration calib;
  if (!cvslam::test::eurocCalibration(&calib)) return p;
  auto rect = StereoRectifier::create(calib);
  const auto stamps = cvslam::test::eurocStereoStamps();
  cv::Mat l, r;
  if (!rect.ok() || stamps.size() < 30 || !cvslam::test::loadEurocPair(stamps[30], &l, &r))
    return p;
  if (!rect->rectify(l, r, &p.left, &p.right).ok()) return p;
  p.f = rect->rectified().f;
  p.baseline = rect->rectified().baseline;
  if (small) {
    cv::Mat hl, hr;
    cv::resize(p.left, hl, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    cv::resize(p.right, hr, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    const cv::Rect roi((hl.cols - 320) / 2, 0, 320, 240);
    p.left = hl(roi).clone();
    p.right = hr(roi).clone();
    p.f *= 0.5;
  }
  return p;
}

void frontEnd(benchmark::State& state) {
  cv::setNumThreads(1);
  const bool small = state.range(0) == 0;
  const auto type = static_cast<DetectorType>(state.range(1));
  const Pair p = loadPair(small);
  if (p.left.empty()) {
    state.SkipWithError("EuRoC micro data missing");
    return;
  }
  StereoFrontEndOptions o;
  o.detector.type = type;
  o.detector.adaptive_sift.upsample_first_octave = state.range(2) == 0;
  o.stereo.focal_px = p.f;
  o.stereo.baseline_m = p.baseline;
  std::shared_ptr<const Vocabulary> vocab;
  if (type != DetectorType::kOrb) {
    auto v = Vocabulary::load(std::string(CVSLAM_SOURCE_DIR) + "/config/vocabulary_sift.cvoc");
    if (!v.ok()) {
      state.SkipWithError(v.status().message().c_str());
      return;
    }
    vocab = std::make_shared<const Vocabulary>(std::move(v.value()));
  }
  auto fe = StereoFrontEnd::create(o, vocab);
  if (!fe.ok()) {
    state.SkipWithError(fe.status().message().c_str());
    return;
  }
  std::vector<cvslam::StereoObservation> obs;
  for (auto _ : state) {
    if (!fe->process(p.left, p.right, &obs).ok()) state.SkipWithError("process failed");
    benchmark::DoNotOptimize(obs.data());
  }
  state.counters["features_left"] = static_cast<double>(fe->lastFrame().left.size());
  state.counters["stereo_matches"] = static_cast<double>(obs.size());
}

// Args: {0: 320×240, 1: 752×480}, {detector: 0 adaptive SIFT, 1 SIFT, 2 ORB}, {adaptive SIFT
// with upsample_first_octave: 0 true (default), 1 false}.
BENCHMARK(frontEnd)
    ->ArgNames({"size752", "detector", "no_upsample"})
    ->Args({0, 2, 0})
    ->Args({1, 2, 0})
    ->Args({0, 0, 0})
    ->Args({1, 0, 0})
    ->Args({0, 0, 1})
    ->Args({1, 0, 1})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

// What OpenCV 4.6's SIFT builds before its extremum search (sift.dispatch.cpp: createInitialImage
// with the doubled image, buildGaussianPyramid, buildDoGPyramid), with the same primitives.
std::size_t siftPyramid(const cv::Mat& gray, int layers, double sigma) {
  cv::Mat f, base;
  gray.convertTo(f, CV_32F);
  cv::resize(f, base, cv::Size(f.cols * 2, f.rows * 2), 0, 0, cv::INTER_LINEAR_EXACT);
  const double init = std::sqrt(std::max(sigma * sigma - 4 * 0.5 * 0.5, 0.01));
  cv::GaussianBlur(base, base, cv::Size(), init, init);
  const int octaves =
      static_cast<int>(std::lround(std::log2(std::min(base.cols, base.rows)) - 2)) + 1;
  std::vector<double> sig(static_cast<std::size_t>(layers + 3));
  sig[0] = sigma;
  const double k = std::pow(2.0, 1.0 / layers);
  for (int i = 1; i < layers + 3; ++i) {
    const double prev = std::pow(k, i - 1) * sigma;
    sig[static_cast<std::size_t>(i)] = std::sqrt((prev * k) * (prev * k) - prev * prev);
  }
  std::vector<cv::Mat> g(static_cast<std::size_t>(octaves * (layers + 3)));
  std::vector<cv::Mat> dog;
  for (int o = 0; o < octaves; ++o)
    for (int i = 0; i < layers + 3; ++i) {
      cv::Mat& dst = g[static_cast<std::size_t>(o * (layers + 3) + i)];
      if (o == 0 && i == 0) {
        dst = base;
      } else if (i == 0) {
        const cv::Mat& src = g[static_cast<std::size_t>((o - 1) * (layers + 3) + layers)];
        cv::resize(src, dst, cv::Size(src.cols / 2, src.rows / 2), 0, 0, cv::INTER_NEAREST);
      } else {
        const double si = sig[static_cast<std::size_t>(i)];
        cv::GaussianBlur(g[static_cast<std::size_t>(o * (layers + 3) + i - 1)], dst, cv::Size(), si,
                         si);
      }
      if (i > 0) dog.push_back(dst - g[static_cast<std::size_t>(o * (layers + 3) + i - 1)]);
    }
  return dog.size();
}

// The adaptive-SIFT front end's stages on the left image (or the pair), single thread, for the
// profile split: 0 DoG energy + eq. 4.6 (adaptScaleFactor), 1 whole detectAdaptiveSift,
// 2 OpenCV SIFT detect only (adapted parameters), 3 stereo matching of the pair, 4 word ids of
// the left features, 5 a replica of OpenCV 4.6's Gaussian + DoG pyramid (siftPyramid); third
// argument as in frontEnd (1: upsample_first_octave false). Stage 2 − 5 ≈ extremum search and
// orientations, 1 − 2 − 0 ≈ descriptors.
void adaptiveSiftStage(benchmark::State& state) {
  cv::setNumThreads(1);
  const bool small = state.range(0) == 0;
  const int stage = static_cast<int>(state.range(1));
  const Pair p = loadPair(small);
  if (p.left.empty()) {
    state.SkipWithError("EuRoC micro data missing");
    return;
  }
  AdaptiveSiftOptions a;
  a.upsample_first_octave = state.range(2) == 0;
  // What OpenCV's SIFT is given (adaptive_sift.cpp): the image or its 2× area-downsampled copy.
  cv::Mat sift_input = p.left;
  if (!a.upsample_first_octave)
    cv::resize(p.left, sift_input, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  Features fl, fr;
  if (!detectAdaptiveSift(p.left, a, &fl).ok() || !detectAdaptiveSift(p.right, a, &fr).ok()) {
    state.SkipWithError("detection failed");
    return;
  }
  StereoMatchOptions so;
  so.focal_px = p.f;
  so.baseline_m = p.baseline;
  auto v = Vocabulary::load(std::string(CVSLAM_SOURCE_DIR) + "/config/vocabulary_sift.cvoc");
  if (!v.ok()) {
    state.SkipWithError(v.status().message().c_str());
    return;
  }
  const ScaleFactorChoice c = adaptScaleFactor(p.left, a);
  for (auto _ : state) {
    if (stage == 0) {
      benchmark::DoNotOptimize(adaptScaleFactor(p.left, a).k);
    } else if (stage == 1) {
      Features f;
      benchmark::DoNotOptimize(detectAdaptiveSift(p.left, a, &f).ok());
    } else if (stage == 2) {
      const double dog = std::max(a.min_contrast, a.contrast_gain * std::sqrt(c.energy));
      auto sift = cv::SIFT::create(a.max_features, c.octave_layers, dog * c.octave_layers / 255.0,
                                   a.edge_threshold, a.sigma0, CV_8U);
      std::vector<cv::KeyPoint> kp;
      sift->detect(sift_input, kp);
      benchmark::DoNotOptimize(kp.data());
    } else if (stage == 5) {
      benchmark::DoNotOptimize(siftPyramid(sift_input, c.octave_layers, a.sigma0));
    } else if (stage == 3) {
      const auto m = matchStereo(fl, fr, so);
      benchmark::DoNotOptimize(m.data());
    } else {
      const auto w = v->words(fl);
      benchmark::DoNotOptimize(w.data());
    }
  }
  state.counters["octave_layers"] = c.octave_layers;
  state.counters["features_left"] = static_cast<double>(fl.size());
}

BENCHMARK(adaptiveSiftStage)
    ->ArgNames({"size752", "stage", "no_upsample"})
    ->ArgsProduct({{0, 1}, {0, 1, 2, 3, 4, 5}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

// Brute-force matching of one 752×480 image's features against another's (all pairs, DistRatio
// test, mutual check): criterion 0 L∞, 1 L2, 2 angle (SIFT), 3 Hamming (ORB).
void bruteForceMatch(benchmark::State& state) {
  cv::setNumThreads(1);
  const int criterion = static_cast<int>(state.range(0));
  const Pair p = loadPair(false);
  if (p.left.empty()) {
    state.SkipWithError("EuRoC micro data missing");
    return;
  }
  DetectorOptions d;
  d.type = criterion == 3 ? DetectorType::kOrb : DetectorType::kAdaptiveSift;
  auto det = makeFeatureDetector(d);
  Features a, b;
  if (!det.ok() || !(*det)->detect(p.left, &a).ok() || !(*det)->detect(p.right, &b).ok()) {
    state.SkipWithError("detection failed");
    return;
  }
  MatchOptions o;
  o.norm = criterion == 0 ? MatchNorm::kLinf : criterion == 2 ? MatchNorm::kAngle : MatchNorm::kL2;
  std::size_t n = 0;
  for (auto _ : state) {
    const auto m = matchDescriptors(a, b, o);
    n = m.size();
    benchmark::DoNotOptimize(m.data());
  }
  state.counters["pairs"] = static_cast<double>(a.size() * b.size());
  state.counters["matches"] = static_cast<double>(n);
}

BENCHMARK(bruteForceMatch)
    ->ArgNames({"criterion"})
    ->DenseRange(0, 3)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
