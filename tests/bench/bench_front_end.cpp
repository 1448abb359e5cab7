// Whole stereo front end per pair (detect + describe both images + stereo match + word ids),
// single thread, on the real rectified EuRoC V1_01 pair at 752×480 and a 320×240 version
// (half-size, centre crop). Targets (DESIGN.md §5 brief): ORB ≤ 15 ms / ≤ 40 ms.
//   ./build/tests/bench_front_end --benchmark_repetitions=3

#include <benchmark/benchmark.h>

#include <memory>
#include <opencv2/imgproc.hpp>

#include "../core/vision_test_data.h"
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

// Args: {0: 320×240, 1: 752×480}, {detector: 0 adaptive SIFT, 1 SIFT, 2 ORB}.
BENCHMARK(frontEnd)
    ->ArgNames({"size752", "detector"})
    ->Args({0, 2})
    ->Args({1, 2})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

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
