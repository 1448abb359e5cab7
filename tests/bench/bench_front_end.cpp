// Whole stereo front end per pair (detect + describe both images + stereo match + word ids;
// fast_sift: detect the left image, search the right along rows, describe the matched),
// single thread, on the real rectified EuRoC V1_01 pair at 752×480 and a 320×240 version
// (half-size, centre crop). Issue 15 targets: fast_sift ≤ 20 / ≤ 8 ms per pair (median) and
// ≥ 4× faster than adaptive SIFT in the same run (fastVsReference gives the ratio).
//   ./build/tests/bench_front_end --benchmark_repetitions=3

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <memory>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "../core/vision_test_data.h"
#include "cvslam/render/stereo_renderer.h"
#include "cvslam/vision/adaptive_sift.h"
#include "cvslam/vision/descriptor_matcher.h"
#include "cvslam/vision/fast_sift.h"
#include "cvslam/vision/row_stereo_search.h"
#include "cvslam/vision/stereo_front_end.h"
#include "cvslam/vision/stereo_rectifier.h"
#include "render_test_scenes.h"

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

// One thread, and the pair of state.range(0) (0: 320×240, 1: 752×480); empty (benchmark
// skipped) without the EuRoC micro data.
Pair pairOrSkip(benchmark::State& state) {
  cv::setNumThreads(1);
  Pair p = loadPair(state.range(0) == 0);
  if (p.left.empty()) state.SkipWithError("EuRoC micro data missing");
  return p;
}

// The front end of the shipped defaults with `type`, for the pair's camera; an error message
// in *error when it cannot be made.
cvslam::Expected<StereoFrontEnd> makeFrontEnd(const Pair& p, DetectorType type, bool upsample,
                                              int max_observations = 0) {
  StereoFrontEndOptions o;
  o.max_observations = max_observations;
  o.detector.type = type;
  o.detector.adaptive_sift.upsample_first_octave = upsample;
  o.stereo.focal_px = p.f;
  o.stereo.baseline_m = p.baseline;
  std::shared_ptr<const Vocabulary> vocab;
  // ORB has its own vocabulary, SWIF none (docs/front_end.md "SWIF").
  if (type != DetectorType::kOrb && type != DetectorType::kSwif) {
    auto v = Vocabulary::load(std::string(CVSLAM_SOURCE_DIR) + "/config/vocabulary_sift.cvoc");
    if (!v.ok()) return v.status();
    vocab = std::make_shared<const Vocabulary>(std::move(v.value()));
  }
  return StereoFrontEnd::create(o, vocab);
}

void frontEnd(benchmark::State& state) {
  const auto type = static_cast<DetectorType>(state.range(1));
  const Pair p = pairOrSkip(state);
  if (p.left.empty()) return;
  auto fe = makeFrontEnd(p, type, state.range(2) == 0);
  if (!fe.ok()) {
    state.SkipWithError(fe.status().message().c_str());
    return;
  }
  std::vector<cvslam::StereoObservation> obs;
  for (auto _ : state) {
    if (!fe->process(p.left, p.right, &obs).ok()) state.SkipWithError("process failed");
    benchmark::DoNotOptimize(obs.data());
  }
  state.counters["features_left"] = static_cast<double>(fe->lastFrame().left_detected);
  state.counters["stereo_matches"] = static_cast<double>(obs.size());
}

// Args: {0: 320×240, 1: 752×480}, {detector: 0 adaptive SIFT, 1 SIFT, 2 ORB, 3 fast SIFT,
// 4 SWIF},
// {adaptive SIFT with upsample_first_octave: 0 true (default), 1 false}.
BENCHMARK(frontEnd)
    ->ArgNames({"size752", "detector", "no_upsample"})
    ->Args({0, 3, 0})
    ->Args({1, 3, 0})
    ->Args({0, 2, 0})
    ->Args({1, 2, 0})
    ->Args({0, 4, 0})
    ->Args({1, 4, 0})
    ->Args({0, 0, 0})
    ->Args({1, 0, 0})
    ->Args({0, 0, 1})
    ->Args({1, 0, 1})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// CPU time of this thread [ms]: the per-core cost, unaffected by other processes on the machine.
double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

// fast_sift against the reference (adaptive SIFT, shipped defaults) in the same run, pair by
// pair alternately: counters are the medians of the thread CPU time per pair [ms] and their
// ratio (speedup). Args: size752, budget (fast_sift's describe_budget; config/agent.yaml: 150).
void fastVsReference(benchmark::State& state) {
  const Pair p = pairOrSkip(state);
  if (p.left.empty()) return;
  auto fast = makeFrontEnd(p, DetectorType::kFastSift, true, static_cast<int>(state.range(1)));
  auto ref = makeFrontEnd(p, DetectorType::kAdaptiveSift, true);
  if (!fast.ok() || !ref.ok()) {
    state.SkipWithError("front end creation failed");
    return;
  }
  std::vector<cvslam::StereoObservation> obs_fast, obs_ref;
  std::vector<double> t_fast, t_ref;
  auto timed = [](StereoFrontEnd& fe, const Pair& pair, std::vector<cvslam::StereoObservation>* o) {
    const double t0 = threadCpuMs();
    const bool ok = fe.process(pair.left, pair.right, o).ok();
    return ok ? threadCpuMs() - t0 : -1.0;
  };
  for (auto _ : state) {
    t_ref.push_back(timed(*ref, p, &obs_ref));
    t_fast.push_back(timed(*fast, p, &obs_fast));
  }
  state.counters["reference_ms"] = median(t_ref);
  state.counters["fast_ms"] = median(t_fast);
  state.counters["speedup"] = median(t_ref) / median(t_fast);
  state.counters["reference_obs"] = static_cast<double>(obs_ref.size());
  state.counters["fast_obs"] = static_cast<double>(obs_fast.size());
}

BENCHMARK(fastVsReference)
    ->ArgNames({"size752", "budget"})
    ->ArgsProduct({{0, 1}, {0, 150}})
    ->Iterations(11)
    ->Unit(benchmark::kMillisecond);

// fast_sift's stages on the pair, single thread: 0 DoG energy + eq. 4.6, 1 detect (scale space
// + extrema + grid, includes 0), 2 row search of the detected keypoints on the right, 3
// orientation + descriptors of the matched keypoints, 4 word ids of those, 5 scale space only
// (part of 1), 6 extremum search and localisation only (part of 1).
void fastSiftStage(benchmark::State& state) {
  const int stage = static_cast<int>(state.range(1));
  const Pair p = pairOrSkip(state);
  if (p.left.empty()) return;
  const AdaptiveSiftOptions a;
  FastSift sift(a, FastSiftOptions());
  StereoMatchOptions so;
  so.focal_px = p.f;
  so.baseline_m = p.baseline;
  auto v = Vocabulary::load(std::string(CVSLAM_SOURCE_DIR) + "/config/vocabulary_sift.cvoc");
  std::vector<cv::KeyPoint> detected;
  if (!v.ok() || !sift.detect(p.left, &detected).ok()) {
    state.SkipWithError("setup failed");
    return;
  }
  RowStereoSearch search;
  std::vector<RowStereoMatch> matches;
  search.search(p.left, p.right, detected, so, RowSearchOptions(), &matches);
  Features matched;
  for (const RowStereoMatch& m : matches)
    matched.keypoints.push_back(detected[static_cast<std::size_t>(m.left)]);
  sift.describe(&matched.keypoints, &matched.descriptors);
  const ScaleFactorChoice c = adaptScaleFactor(p.left, a);
  SiftScaleSpace space;
  const FastSiftOptions fo;
  space.build(p.left, c.octave_layers, a.sigma0, fo.max_octaves, fo.baseScale(p.left.size()));
  const double dog_threshold = std::max(a.min_contrast, a.contrast_gain * std::sqrt(c.energy));
  std::vector<cv::KeyPoint> extrema;
  for (auto _ : state) {
    if (stage == 0) {
      benchmark::DoNotOptimize(adaptScaleFactor(p.left, a).k);
    } else if (stage == 5) {
      space.build(p.left, c.octave_layers, a.sigma0, fo.max_octaves, fo.baseScale(p.left.size()));
    } else if (stage == 6) {
      space.findExtrema(dog_threshold, a.edge_threshold, &extrema);
      benchmark::DoNotOptimize(extrema.data());
    } else if (stage == 1) {
      benchmark::DoNotOptimize(sift.detect(p.left, &detected).ok());
    } else if (stage == 2) {
      search.search(p.left, p.right, detected, so, RowSearchOptions(), &matches);
      benchmark::DoNotOptimize(matches.data());
    } else if (stage == 3) {
      std::vector<cv::KeyPoint> k = matched.keypoints;
      cv::Mat d;
      sift.describe(&k, &d);
      benchmark::DoNotOptimize(d.data);
    } else {
      const auto w = v->words(matched);
      benchmark::DoNotOptimize(w.data());
    }
  }
  state.counters["detected"] = static_cast<double>(detected.size());
  state.counters["matched"] = static_cast<double>(matched.size());
  state.counters["octave_layers"] = c.octave_layers;
  state.counters["extrema"] = static_cast<double>(extrema.size());
}

BENCHMARK(fastSiftStage)
    ->ArgNames({"size752", "stage"})
    ->ArgsProduct({{0, 1}, {0, 1, 2, 3, 4, 5, 6}})
    ->Unit(benchmark::kMillisecond);

// A rendered sequence through fast_sift and the reference: 40 frames, 5 cm apart, rendered
// once before timing; frames per second of CPU time (one thread), ms per pair, observations
// per pair and the stereo precision against the renderer's depth (a match is right when its
// disparity is within 1 px of f·b/z at the left pixel and its row within 1 px). World 0: the
// hall at 752×480 with an EuRoC-like camera (f = 458 px, b = 0.11 m); 1: the aerial world at
// 320×240 with the thesis's camera (Table 5.6: α = 560, b = 0.20 m, looking down), as
// thesis_loop and team3_aerial fly it.
void renderedSequence(benchmark::State& state) {
  cv::setNumThreads(1);
  const bool aerial = state.range(1) == 1;
  cvslam::StereoCamera cam = cvslam::test::euroCCamera(752, 480);
  if (aerial) {
    cvslam::StereoCameraOptions o;
    o.width = 320;
    o.height = 240;
    o.cx = 160;
    o.cy = 120;
    cam = cvslam::StereoCamera(o);
  }
  const auto kind = aerial ? cvslam::render::WorldKind::kAerial : cvslam::render::WorldKind::kHall;
  cvslam::render::StereoRenderer renderer(cvslam::test::makeWorld(kind), cam);
  const auto [p0, e0] = aerial ? cvslam::test::aerialPose() : cvslam::test::hallPose();
  std::vector<cvslam::render::StereoRendering> frames;
  for (int k = 0; k < 40; ++k)
    frames.push_back(
        renderer.render(p0 + Eigen::Vector3d(0.05, 0.02, 0.0) * k, e0, static_cast<uint64_t>(k)));
  Pair p;
  p.f = cam.options().fx;
  p.baseline = cam.options().baseline;
  auto fe = makeFrontEnd(p, static_cast<DetectorType>(state.range(0)), true,
                         static_cast<int>(state.range(2)));
  if (!fe.ok()) {
    state.SkipWithError(fe.status().message().c_str());
    return;
  }
  std::vector<cvslam::StereoObservation> obs;
  std::vector<double> ms;
  long checked = 0, correct = 0;
  for (auto _ : state) {
    for (const auto& f : frames) {
      const double t0 = threadCpuMs();
      if (!fe->process(f.left.image, f.right.image, &obs).ok()) state.SkipWithError("process");
      ms.push_back(threadCpuMs() - t0);
      const cv::Mat1f depth = f.left.depthMap();
      for (const cvslam::StereoObservation& o : obs) {
        const float z = depth(cvRound(o.z(1)), cvRound(o.z(0)));
        if (!(z > 0)) continue;
        ++checked;
        const double d_true = p.f * p.baseline / z;
        if (std::abs(o.z(0) - o.z(2) - d_true) <= 1.0 && std::abs(o.z(1) - o.z(3)) <= 1.0)
          ++correct;
      }
    }
  }
  double total = 0.0;
  for (double t : ms) total += t;
  state.counters["frames_per_cpu_s"] = 1e3 * static_cast<double>(ms.size()) / total;
  state.counters["median_ms_per_pair"] = median(ms);
  state.counters["obs_per_pair"] = static_cast<double>(checked) / static_cast<double>(ms.size());
  state.counters["stereo_precision"] =
      checked > 0 ? static_cast<double>(correct) / static_cast<double>(checked) : 0.0;
}

// Args: detector (3 fast SIFT; 0 adaptive SIFT, the reference), world (0 hall 752×480, 1 aerial
// 320×240), max_observations (0 = all; fast SIFT describes only that many).
BENCHMARK(renderedSequence)
    ->ArgNames({"detector", "aerial320", "max_obs"})
    ->ArgsProduct({{3, 0}, {0, 1}, {0}})
    ->Args({3, 0, 300})
    ->Args({3, 1, 200})
    ->Args({3, 0, 150})
    ->Args({3, 1, 150})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

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
  const int stage = static_cast<int>(state.range(1));
  const Pair p = pairOrSkip(state);
  if (p.left.empty()) return;
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
