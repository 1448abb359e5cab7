// cvslam_mosaic — image mosaic (thesis §4.3) of one UAV or of a team from a finished
// simulated run: each UAV's left images are rendered at its true poses (what its camera
// saw), placed with its estimated poses as the prior and refined by registration; the
// renderer's truth gives the registration error and the true texture the PSNR of
// super-resolved patches. A thin shell: the algorithms are in common/mosaic/.

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "cvslam/geometry/euler.h"
#include "cvslam/io/cli.h"
#include "cvslam/io/config_node.h"
#include "cvslam/io/run_reader.h"
#include "cvslam/mosaic/mosaic_config.h"
#include "cvslam/render/ground_texture.h"
#include "cvslam/render/stereo_renderer.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/simrun/scenario_rendering.h"

namespace {

namespace mosaic = cvslam::mosaic;

constexpr const char* kUsage =
    R"(usage: cvslam_mosaic --scenario FILE --run DIR [--agents IDS] [--out PNG] [options]

Builds a ground mosaic (thesis §4.3) from the left images of the given UAVs of a simulated
run (cvslam_run --out DIR): images rendered at the true poses, placed with the estimated
poses (agent_<id>/states.csv) as the prior, registered (adaptive SIFT + RANSAC homography),
adjusted, photometrically corrected and blended. One agent: its own mosaic; several: the
cooperative mosaic in the team frame. Prints the registration error against the renderer's
truth [mosaic px] and the PSNR of super-resolved patches vs the plain mosaic.

  --scenario FILE     the run's scenario (config/scenarios/*.yaml) (required)
  --run DIR           run folder with agent_<id>/states.csv and truth.csv (required)
  --agents IDS        comma-separated agent ids (default: every agent of the run)
  --config FILE       mosaic options (default: config/mosaic.yaml of the source tree)
  --duration S        use the first S seconds of the run (default: all)
  --period S          one frame per UAV every S seconds (overrides evaluation.frame_period)
  --world KIND        render world aerial|hall (default: the run's, see run.json)
  --out PNG           the mosaic at full resolution
  --preview PNG       the mosaic downscaled to at most --preview-px on its longer side
  --preview-px N      (default 1200)
  --sr-sample PNG     one super-resolution patch: truth | plain mosaic | super-resolved
  --true-prior        use the true poses as the prior instead of the estimates (baseline)
  -h, --help          this text
)";

int fail(const std::string& message) {
  std::cerr << "cvslam_mosaic: " << message << '\n';
  return 2;
}

// cv::imwrite throws on a name without a known image extension.
bool writeImage(const std::string& path, const cv::Mat& image) {
  try {
    return cv::imwrite(path, image);
  } catch (const cv::Exception&) {
    return false;
  }
}

struct Args {
  std::string scenario, run, config, world, out, preview, sr_sample;
  std::vector<int> agents;
  double duration = 0.0, period = -1.0;
  int preview_px = 1200;
  bool true_prior = false;
};

struct Inputs {
  std::vector<mosaic::MosaicFrame> frames;
  std::vector<std::vector<mosaic::TruthPoint>> truth;
};

// The truth row nearest in time to t (rows sorted by time).
const cvslam::StateRecord* nearest(const std::vector<cvslam::StateRecord>& rows, double t) {
  auto it = std::lower_bound(rows.begin(), rows.end(), t,
                             [](const cvslam::StateRecord& r, double x) { return r.t < x; });
  const cvslam::StateRecord* best = nullptr;
  if (it != rows.end()) best = &*it;
  if (it != rows.begin() && (!best || t - std::prev(it)->t < best->t - t)) best = &*std::prev(it);
  return best;
}

// Renders one agent's frames (true pose) and pairs them with its estimated poses.
cvslam::Status agentFrames(const Args& a, const cvslam::sim::AgentSpec& spec,
                           const std::shared_ptr<const cvslam::render::World>& world,
                           const cvslam::render::RenderOptions& render,
                           const mosaic::EvaluationOptions& eval,
                           const mosaic::MosaicOptions& mosaic_options,
                           std::vector<std::pair<double, std::size_t>>* order, Inputs* in) {
  const std::string dir = a.run + "/agent_" + std::to_string(spec.id);
  auto est = cvslam::readStateTable(dir + "/states.csv");
  if (!est.ok()) return est.status();
  auto truth = cvslam::readStateTable(dir + "/truth.csv");
  if (!truth.ok()) return truth.status();
  if (est->empty() || truth->empty()) return cvslam::Status::Error(dir + ": no states");
  // The UAV's estimated map gives the ground plane under each frame (its own frame, N).
  auto landmarks = cvslam::readLandmarks(dir + "/landmarks.csv");
  if (!landmarks.ok()) return landmarks.status();
  std::vector<Eigen::Vector3d> ground;
  for (const cvslam::LandmarkRecord& l : *landmarks) ground.push_back(l.p_LinN);
  const cvslam::StereoCamera camera(spec.camera);
  const cvslam::render::StereoRenderer renderer(world, camera, render);
  const cvslam::StereoCameraOptions& c = spec.camera;
  Eigen::Matrix3d K;
  K << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1;
  const double t0 = est->front().t;
  double last = -1e300;
  uint64_t index = 0;
  for (const cvslam::StateRecord& s : *est) {
    if (a.duration > 0.0 && s.t > t0 + a.duration) break;
    if (s.t < last + eval.frame_period) continue;
    const cvslam::StateRecord* tr = nearest(*truth, s.t);
    if (!tr || std::abs(tr->t - s.t) > 0.5 / spec.camera_rate_hz) continue;
    last = s.t;
    const Eigen::Vector3d p_true = tr->x.head<3>(), e_true = tr->x.tail<3>();
    const auto left = renderer.render(p_true, e_true, index++).left;
    mosaic::MosaicFrame f;
    f.image = left.image;
    f.K = K;
    f.agent = spec.id;
    const cvslam::StateRecord& prior = a.true_prior ? *tr : s;
    const Eigen::Vector3d p_est = prior.x.head<3>(), e_est = prior.x.tail<3>();
    f.R_NtoC = c.R_BtoC * cvslam::rotationNavToBody(e_est);
    f.p_CinN = p_est + cvslam::rotationBodyToNav(e_est) * c.p_CinB;
    f.ground_plane = mosaic::groundPlaneFromPoints(f, ground, mosaic_options.min_ground_points,
                                                   mosaic_options.min_ground_spread);
    std::vector<mosaic::TruthPoint> pts;
    const int g = eval.truth_grid;
    for (int j = 1; j < g; ++j)
      for (int i = 1; i < g; ++i) {
        const Eigen::Vector2d px(c.width * i / double(g), c.height * j / double(g));
        if (auto sp = left.surfaceAt(px.x(), px.y())) pts.push_back({px, sp->p_N.head<2>()});
      }
    order->emplace_back(s.t, in->frames.size());
    in->frames.push_back(f);
    in->truth.push_back(std::move(pts));
  }
  return cvslam::Status::Ok();
}

void printRegistration(const char* what, const mosaic::RegistrationError& e) {
  std::printf(
      "%s: median %.2f  p90 %.2f  (after a 2-D similarity; raw median %.2f  p90 %.2f) "
      "[mosaic px, %d points]\n",
      what, e.aligned.median, e.aligned.p90, e.raw.median, e.raw.p90, e.aligned.count);
}

// The similarity mosaic → true mosaic pixels from the truth points placed near a patch:
// the patch's own registration offset, so that its PSNR measures detail, not the
// (separately reported) registration error.
Eigen::Matrix3d localAlignment(const mosaic::MosaicGrid& grid,
                               const std::vector<mosaic::PlacedTruth>& placed,
                               const Eigen::Vector2d& origin, double size) {
  std::vector<mosaic::PlacedTruth> near;
  for (const mosaic::PlacedTruth& f : placed) {
    mosaic::PlacedTruth g{f.H, {}};
    for (const mosaic::TruthPoint& t : f.points) {
      const Eigen::Vector2d m = mosaic::applyHomography(f.H, t.pixel) - origin;
      if (m.minCoeff() > -size && m.maxCoeff() < 2 * size) g.points.push_back(t);
    }
    if (!g.points.empty()) near.push_back(std::move(g));
  }
  return mosaic::registrationError(grid, near).similarity;
}

// Super-resolution patches spread over the frames (every n-th frame's footprint centre).
void superResolution(const Args& a, const mosaic::MosaicConfig& cfg,
                     const mosaic::MosaicBuilder& builder,
                     const std::vector<mosaic::FramePlacement>& placements,
                     const cvslam::render::World& world, double exposure,
                     const std::vector<mosaic::PlacedTruth>& placed) {
  const auto truth = [&](double x, double y) {
    return exposure * cvslam::render::terrainRadiance(world, x, y);
  };
  std::vector<double> plain, sr, gain;
  const int want = cfg.evaluation.sr_patches;
  const std::size_t n = builder.frames().size();
  for (int i = 0; i < want && n > 0; ++i) {
    const std::size_t k =
        (2 * static_cast<std::size_t>(i) + 1) * n / (2 * static_cast<std::size_t>(want));
    const mosaic::MosaicFrame& f = builder.frames()[k];
    const Eigen::Vector2d centre = mosaic::applyHomography(
        placements[k].H, Eigen::Vector2d(0.5 * f.image.cols, 0.5 * f.image.rows));
    const Eigen::Vector2d origin =
        (centre.array() - 0.5 * cfg.evaluation.sr_patch_px).round().matrix();
    const Eigen::Matrix3d mosaic_to_true =
        localAlignment(builder.grid(), placed, origin, cfg.evaluation.sr_patch_px);
    auto p = mosaic::evaluateSuperResolution(builder, placements, origin, cfg.super_resolution,
                                             cfg.evaluation, truth, mosaic_to_true);
    if (!p.ok()) continue;
    plain.push_back(p->psnr_plain_db);
    sr.push_back(p->psnr_sr_db);
    gain.push_back(p->psnr_sr_db - p->psnr_plain_db);
    if (!a.sr_sample.empty() && plain.size() == 1) {
      cv::Mat row, out;
      cv::hconcat(std::vector<cv::Mat>{p->truth, p->plain, p->sr}, row);
      row.convertTo(out, CV_8U);
      if (!writeImage(a.sr_sample, out))
        std::fprintf(stderr, "cvslam_mosaic: cannot write %s\n", a.sr_sample.c_str());
    }
  }
  const auto med = [](std::vector<double> v) { return mosaic::errorStats(std::move(v)).median; };
  if (gain.empty()) {
    std::printf("super-resolution: no patch seen by %d frames\n", cfg.evaluation.sr_min_frames);
    return;
  }
  std::printf(
      "super-resolution x%d (Papoulis-Gerchberg, %d it.): %zu patches of %d px, "
      "median PSNR plain %.2f dB, SR %.2f dB, gain %+.2f dB (min %+.2f, max %+.2f)\n",
      cfg.super_resolution.scale, cfg.super_resolution.iterations, gain.size(),
      cfg.evaluation.sr_patch_px, med(plain), med(sr), med(gain),
      *std::min_element(gain.begin(), gain.end()), *std::max_element(gain.begin(), gain.end()));
}

int writeOutputs(const Args& a, const mosaic::MosaicBuilder& builder) {
  const cv::Mat image = builder.image();
  if (!a.out.empty() && !writeImage(a.out, image)) return fail("cannot write " + a.out);
  if (!a.preview.empty()) {
    const double f = std::min(1.0, a.preview_px / double(std::max(image.cols, image.rows)));
    cv::Mat small;
    cv::resize(image, small, cv::Size(), f, f, cv::INTER_AREA);
    if (!writeImage(a.preview, small)) return fail("cannot write " + a.preview);
  }
  return 0;
}

int run(const Args& a) {
  for (const std::string* path : {&a.out, &a.preview, &a.sr_sample})
    if (!path->empty() && !cv::haveImageWriter(*path))
      return fail("no image format for " + *path + " (use .png)");
  auto cfg = mosaic::MosaicConfig::loadFile(a.config);
  if (!cfg.ok()) return fail(cfg.status().message());
  if (a.period >= 0.0) cfg->evaluation.frame_period = a.period;
  auto scenario = cvslam::sim::Scenario::loadFile(a.scenario);
  if (!scenario.ok()) return fail(scenario.status().message());
  auto info = cvslam::readRunInfo(a.run);
  if (!info.ok()) return fail(info.status().message());
  // The world the run rendered: the scenario's `render:` world with cvslam_run's --world
  // override of its kind (run.json), as cvslam_run builds it.
  auto rendering = cvslam::ScenarioRendering::parse(*scenario);
  if (!rendering.ok()) return fail(rendering.status().message());
  cvslam::render::WorldOptions world_options =
      rendering->world.value_or(cvslam::render::WorldOptions());
  const std::string kind = a.world.empty() ? info->world : a.world;
  if (!kind.empty()) {
    auto node = cvslam::ConfigNode::fromString("kind: " + kind, "--world");
    if (!node.ok()) return fail(node.status().message());
    if (auto s = world_options.load(*node); !s.ok()) return fail(s.message());
  }
  auto world = cvslam::render::World::create(world_options);
  if (!world.ok()) return fail(world.status().message());
  std::vector<int> ids = a.agents;
  if (ids.empty()) {
    auto listed = cvslam::listAgentIds(a.run);
    if (!listed.ok()) return fail(listed.status().message());
    ids = *listed;
  }
  Inputs in;
  std::vector<std::pair<double, std::size_t>> order;
  for (int id : ids) {
    auto spec = std::find_if(scenario->agents.begin(), scenario->agents.end(),
                             [id](const auto& s) { return s.id == id; });
    if (spec == scenario->agents.end())
      return fail("agent " + std::to_string(id) + " is not in " + a.scenario);
    if (auto s = agentFrames(a, *spec, *world, rendering->options, cfg->evaluation, cfg->mosaic,
                             &order, &in);
        !s.ok())
      return fail(s.message());
  }
  // Time order across UAVs: each frame registers to what the team mapped before it.
  std::stable_sort(order.begin(), order.end());
  std::vector<mosaic::MosaicFrame> frames;
  std::vector<std::vector<mosaic::TruthPoint>> truth;
  for (const auto& [t, k] : order) {
    frames.push_back(in.frames[k]);
    truth.push_back(in.truth[k]);
  }
  auto grid = mosaic::MosaicBuilder::gridCovering(frames, cfg->mosaic);
  if (!grid.ok()) return fail(grid.status().message());
  mosaic::MosaicBuilder builder(*grid, cfg->mosaic, cfg->registration, cfg->photometric);
  for (const auto& f : frames)
    if (auto s = builder.add(f); !s.ok()) return fail(s.message());
  auto placements = builder.finish();
  if (!placements.ok()) return fail(placements.status().message());
  std::vector<mosaic::PlacedTruth> placed, prior;
  int registered = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    placed.push_back({(*placements)[k].H, truth[k]});
    prior.push_back({(*placements)[k].prior, truth[k]});
    registered += (*placements)[k].registered_pairs > 0;
  }
  std::printf(
      "cvslam_mosaic: %zu UAV(s), %zu frames (%d registered to earlier ones), mosaic "
      "%d×%d px at %.3f m/px\n",
      ids.size(), frames.size(), registered, grid->cols, grid->rows, grid->gsd);
  const auto reg = mosaic::registrationError(builder.grid(), placed);
  printRegistration("registration error", reg);
  if (ids.size() > 1)
    for (int id : ids) {
      std::vector<mosaic::PlacedTruth> sub;
      for (std::size_t k = 0; k < frames.size(); ++k)
        if (frames[k].agent == id) sub.push_back(placed[k]);
      const auto e = mosaic::registrationError(builder.grid(), sub);
      std::printf("  UAV %d: median %.2f  p90 %.2f  (after its own similarity; raw median %.2f)\n",
                  id, e.aligned.median, e.aligned.p90, e.raw.median);
    }
  printRegistration("pose prior only   ", mosaic::registrationError(builder.grid(), prior));
  superResolution(a, *cfg, builder, *placements, **world, rendering->options.effects.exposure,
                  placed);
  return writeOutputs(a, builder);
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  a.config = std::string(CVSLAM_CONFIG_DIR) + "/mosaic.yaml";
  CLI::App app("image mosaic of a run", "cvslam_mosaic");
  app.add_option("--scenario", a.scenario)->required()->check(CLI::ExistingFile);
  app.add_option("--run", a.run)->required()->check(CLI::ExistingDirectory);
  app.add_option("--agents", a.agents)->delimiter(',');
  app.add_option("--config", a.config)->check(CLI::ExistingFile);
  app.add_option("--duration", a.duration)->check(cvslam::cli::kPositive);
  app.add_option("--period", a.period)->check(cvslam::cli::kNonNegative);
  app.add_option("--world", a.world)->check(CLI::IsMember({"aerial", "hall"}));
  app.add_option("--out", a.out);
  app.add_option("--preview", a.preview);
  app.add_option("--preview-px", a.preview_px)->check(CLI::Range(16, 100000));
  app.add_option("--sr-sample", a.sr_sample);
  app.add_flag("--true-prior", a.true_prior);
  if (auto exit_code = cvslam::cli::parse(app, argc, argv, kUsage)) return *exit_code;
  return run(a);
}
