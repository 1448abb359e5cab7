// The mosaicking algorithm (thesis §4.3.3.2) on a short rendered flight of two UAVs over the
// aerial world, with perturbed pose estimates as the prior; the renderer's per-pixel truth
// gives each image point's true ground position (the registration error) and
// terrainRadiance() the true texture.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "cvslam/core/random.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/mosaic/mosaic_builder.h"
#include "cvslam/mosaic/mosaic_evaluation.h"
#include "cvslam/render/ground_texture.h"
#include "cvslam/render/stereo_renderer.h"
#include "render_test_scenes.h"

namespace cvslam::mosaic {
namespace {

constexpr int kFramesPerUav = 24;
constexpr int kTruthGrid = 8;  // truth points per image side

struct Flight {
  std::vector<MosaicFrame> frames;
  std::vector<std::vector<TruthPoint>> truth;
};

double gauss(uint64_t& state, double sigma) {
  // Sum of 12 uniforms − 6: approximately N(0, 1), deterministic on every platform.
  double s = -6.0;
  for (int i = 0; i < 12; ++i) s += static_cast<double>(splitmix64(state) >> 11) * 0x1.0p-53;
  return sigma * s;
}

// Two UAVs on antiparallel strips 3 m apart (about half a footprint of overlap), interleaved.
// Estimated poses = truth + a constant offset per UAV + a small random walk.
Flight renderFlight(const render::StereoRenderer& renderer) {
  Flight f;
  const StereoCameraOptions& c = renderer.camera().options();
  Eigen::Matrix3d K;
  K << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1;
  uint64_t state = 17;
  Eigen::Vector3d walk[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  const Eigen::Vector3d offset[2] = {{0.12, -0.08, 0.1}, {-0.10, 0.15, -0.2}};
  for (int k = 0; k < kFramesPerUav; ++k)
    for (int uav = 0; uav < 2; ++uav) {
      const double s = -5.0 + 10.0 * k / (kFramesPerUav - 1);
      const Eigen::Vector3d p_BinN =
          uav == 0 ? Eigen::Vector3d(s, 0.0, -10.0) : Eigen::Vector3d(-s, 3.0, -11.0);
      const Eigen::Vector3d euler(0.02 * std::sin(k), -0.03, uav == 0 ? 0.1 : M_PI - 0.1);
      const auto rendering = renderer.render(p_BinN, euler, static_cast<uint64_t>(k));
      for (int a = 0; a < 3; ++a) walk[uav](a) += gauss(state, 0.01);
      const Eigen::Vector3d p_est = p_BinN + offset[uav] + walk[uav];
      const Eigen::Vector3d e_est = euler + Eigen::Vector3d(0.0, 0.0, uav == 0 ? 0.01 : -0.01);
      MosaicFrame m;
      m.image = rendering.left.image;
      m.K = K;
      m.agent = uav + 1;
      m.R_NtoC = c.R_BtoC * rotationNavToBody(e_est);
      m.p_CinN = p_est + rotationBodyToNav(e_est) * c.p_CinB;
      f.frames.push_back(m);
      std::vector<TruthPoint> pts;
      for (int j = 1; j < kTruthGrid; ++j)
        for (int i = 1; i < kTruthGrid; ++i) {
          const Eigen::Vector2d px(c.width * i / double(kTruthGrid),
                                   c.height * j / double(kTruthGrid));
          if (auto sp = rendering.left.surfaceAt(px.x(), px.y()))
            pts.push_back({px, sp->p_N.head<2>()});
        }
      f.truth.push_back(pts);
    }
  return f;
}

RegistrationError mosaicError(const Flight& f, bool register_frames) {
  MosaicOptions o;
  o.register_frames = register_frames;
  const auto grid = MosaicBuilder::gridCovering(f.frames, o);
  EXPECT_TRUE(grid.ok());
  MosaicBuilder builder(*grid, o, RegistrationOptions{}, PhotometricOptions{});
  for (const MosaicFrame& frame : f.frames) EXPECT_TRUE(builder.add(frame).ok());
  const auto placements = builder.finish();
  EXPECT_TRUE(placements.ok());
  std::vector<PlacedTruth> placed;
  for (std::size_t i = 0; i < f.frames.size(); ++i) {
    placed.push_back({(*placements)[i].H, f.truth[i]});
  }
  return registrationError(builder.grid(), placed);
}

TEST(MosaicFlight, TwoUavMosaicRegistersWithinTwoPixels) {
  const auto world = test::makeWorld(render::WorldKind::kAerial);
  ASSERT_TRUE(world);
  const render::StereoRenderer renderer(world, StereoCamera{});
  const Flight f = renderFlight(renderer);
  const RegistrationError reg = mosaicError(f, true);
  const RegistrationError prior = mosaicError(f, false);
  RecordProperty("median_aligned_px", std::to_string(reg.aligned.median));
  RecordProperty("median_raw_px", std::to_string(reg.raw.median));
  RecordProperty("prior_median_aligned_px", std::to_string(prior.aligned.median));
  // Bound: the median error, once the global offset of the team frame is removed, within
  // 2 mosaic pixels (4 cm at gsd 2 cm; the images' own pixel is 1.8–2.0 cm; 1.51 measured
  // with the defaults of config/mosaic.yaml). Not lower: the terrain is not a plane (4 m
  // facets, 0.3 m bumps), and its parallax between overlapping views (~0.5 px per metre of
  // baseline at 10 m) limits what homographies can reconcile (docs/results/mosaic.md).
  EXPECT_LT(reg.aligned.median, 2.0) << "raw median " << reg.raw.median;
  EXPECT_LT(reg.aligned.p90, 4.0);
  // The pose prior alone (decimetre errors) is far worse: registration does the work.
  EXPECT_GT(prior.aligned.median, 3.0 * reg.aligned.median);
}

TEST(GroundTexture, RenderedNadirImageShowsTheTrueTexture) {
  const auto world = test::makeWorld(render::WorldKind::kAerial);
  ASSERT_TRUE(world);
  const render::StereoRenderer renderer(world, StereoCamera{});
  const auto r = renderer.render(Eigen::Vector3d(2.0, -3.0, -10.0), Eigen::Vector3d::Zero());
  double sum = 0.0;
  int n = 0;
  for (int v = 5; v < r.left.image.rows; v += 7)
    for (int u = 5; u < r.left.image.cols; u += 7) {
      const auto sp = r.left.surfaceAt(u, v);
      ASSERT_TRUE(sp);
      const float truth = render::terrainRadiance(*world, sp->p_N.x(), sp->p_N.y());
      sum += std::abs(truth - r.left.image.at<uint8_t>(v, u));
      ++n;
    }
  // Quantisation (±0.5) only: the renderer shades level 0 at 1.8 cm pixels / 1.5 cm texels.
  EXPECT_LT(sum / n, 1.0);
  // …and a shifted lookup does not match (the test can fail).
  double shifted = 0.0;
  for (int v = 5; v < r.left.image.rows; v += 7)
    for (int u = 5; u < r.left.image.cols; u += 7) {
      const auto sp = r.left.surfaceAt(u, v);
      shifted += std::abs(render::terrainRadiance(*world, sp->p_N.x() + 0.05, sp->p_N.y()) -
                          r.left.image.at<uint8_t>(v, u));
    }
  EXPECT_GT(shifted / n, 5.0);
}

}  // namespace
}  // namespace cvslam::mosaic
