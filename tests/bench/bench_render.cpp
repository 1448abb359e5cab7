// Render time of one stereo pair (both images, shading and ground-truth buffers) for the
// aerial and hall worlds at 320×240 and 752×480, on one core.
//
//   build/tests/bench_render [--write-samples=DIR] [google-benchmark flags]
// With --write-samples, also writes DIR/render_sample_{aerial,hall}.png (left | right).

#include <benchmark/benchmark.h>

#include <opencv2/imgcodecs.hpp>

#include <string>

#include "cvslam/io/cli.h"
#include "cvslam/render/stereo_renderer.h"
#include "render_test_scenes.h"

namespace {

using cvslam::StereoCamera;
using cvslam::StereoCameraOptions;
using cvslam::render::StereoRenderer;
using cvslam::render::WorldKind;

StereoCamera aerialCamera(int width, int height) {
  StereoCameraOptions o;  // thesis Table 5.6: α = 560, 0.20 m baseline, looking down
  o.width = width;
  o.height = height;
  o.cx = 0.5 * width;
  o.cy = 0.5 * height;
  return StereoCamera(o);
}

void renderLoop(benchmark::State& state, WorldKind kind) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  const StereoCamera cam =
      kind == WorldKind::kAerial ? aerialCamera(w, h) : cvslam::test::euroCCamera(w, h);
  StereoRenderer renderer(cvslam::test::makeWorld(kind), cam);
  auto [p, e] = kind == WorldKind::kAerial ? cvslam::test::aerialPose() : cvslam::test::hallPose();
  uint64_t frame = 0;
  for (auto _ : state) {
    // Fly a little between frames so nothing is rendered twice from the same pose.
    const Eigen::Vector3d p_k =
        p + Eigen::Vector3d(0.05, 0.02, 0.0) * static_cast<double>(frame % 40);
    benchmark::DoNotOptimize(renderer.render(p_k, e, frame++));
  }
  state.SetLabel(std::to_string(w) + "x" + std::to_string(h) + " pair");
}

void BM_RenderAerial(benchmark::State& state) {
  renderLoop(state, WorldKind::kAerial);
}
void BM_RenderHall(benchmark::State& state) {
  renderLoop(state, WorldKind::kHall);
}
BENCHMARK(BM_RenderAerial)->Args({320, 240})->Args({752, 480})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RenderHall)->Args({320, 240})->Args({752, 480})->Unit(benchmark::kMillisecond);

void writeSample(const std::string& path, WorldKind kind, const StereoCamera& cam) {
  StereoRenderer renderer(cvslam::test::makeWorld(kind), cam);
  const auto [p, e] =
      kind == WorldKind::kAerial ? cvslam::test::aerialPose() : cvslam::test::hallPose();
  const cvslam::render::StereoRendering out = renderer.render(p, e);
  cv::Mat pair;
  cv::hconcat(out.left.image, out.right.image, pair);
  cv::imwrite(path, pair);
}

}  // namespace

int main(int argc, char** argv) {
  // Google Benchmark takes its own --benchmark_* options out of argv; the rest is ours.
  benchmark::Initialize(&argc, argv);
  CLI::App app("Renders stereo pairs of the aerial and hall worlds (Google Benchmark)",
               "bench_render");
  std::string samples_dir;
  app.add_option("--write-samples", samples_dir,
                 "write one sample pair per world as PNG into this folder and exit (docs/)");
  if (auto exit_code = cvslam::cli::parse(app, argc, argv)) return *exit_code;
  if (!samples_dir.empty()) {
    writeSample(samples_dir + "/render_sample_aerial.png", WorldKind::kAerial,
                aerialCamera(320, 240));
    writeSample(samples_dir + "/render_sample_hall.png", WorldKind::kHall,
                cvslam::test::euroCCamera(376, 240));
    return 0;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
