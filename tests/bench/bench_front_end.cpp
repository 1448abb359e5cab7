// Whole stereo front end per pair (detect + describe both images + stereo match + word ids),
// single thread, on the real rectified EuRoC V1_01 pair at 752×480 and a 320×240 version
// (half-size, centre crop). Targets (DESIGN.md §5 brief): ORB ≤ 15 ms / ≤ 40 ms.
//   ./build/tests/bench_front_end --benchmark_repetitions=3

#include <benchmark/benchmark.h>

#include <memory>
#include <opencv2/imgproc.hpp>

#include "../core/vision_test_data.h"
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

}  // namespace

BENCHMARK_MAIN();
