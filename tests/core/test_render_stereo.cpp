#include <gtest/gtest.h>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "cvslam/io/config_node.h"
#include "cvslam/core/random.h"
#include "cvslam/render/stereo_renderer.h"
#include "render_test_scenes.h"

namespace cvslam {
namespace {

using test::aerialPose;
using test::euroCCamera;
using test::hallPose;
using test::makeWorld;

double meanOf(const cv::Mat& m) {
  return cv::mean(m)[0];
}

TEST(StereoRenderer, SameSeedAndPoseGiveIdenticalImages) {
  const StereoCamera cam;
  render::StereoRenderer a(makeWorld(render::WorldKind::kAerial), cam);
  render::StereoRenderer b(makeWorld(render::WorldKind::kAerial), cam);
  const auto [p, e] = aerialPose();
  const render::StereoRendering ra = a.render(p, e, 3), rb = b.render(p, e, 3);
  EXPECT_EQ(cv::norm(ra.left.image, rb.left.image, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(ra.right.image, rb.right.image, cv::NORM_INF), 0.0);
  // And a different seed gives a different world.
  render::StereoRenderer c(makeWorld(render::WorldKind::kAerial, render::TextureVariant::kHigh, 2), cam);
  EXPECT_GT(cv::norm(ra.left.image, c.render(p, e, 3).left.image, cv::NORM_L1), 0.0);
}

TEST(StereoRenderer, NoisyRenderingIsDeterministicPerFrame) {
  render::RenderOptions o;
  o.effects.noise_sigma = 3.0;
  render::StereoRenderer r(makeWorld(render::WorldKind::kAerial), StereoCamera(), o);
  const auto [p, e] = aerialPose();
  EXPECT_EQ(cv::norm(r.render(p, e, 7).left.image, r.render(p, e, 7).left.image, cv::NORM_INF), 0);
  EXPECT_GT(cv::norm(r.render(p, e, 7).left.image, r.render(p, e, 8).left.image, cv::NORM_INF), 0);
}

TEST(StereoRenderer, AerialGroundIsTenMetresBelowAtTakeOff) {
  render::StereoRenderer r(makeWorld(render::WorldKind::kAerial), StereoCamera());
  const render::StereoRendering out = r.render({0, 0, -10}, {0, 0, 0});
  const auto centre = out.left.surfaceAt(160, 120);
  ASSERT_TRUE(centre.has_value());
  EXPECT_NEAR(centre->p_N.z(), 0.0, 1e-6);  // the terrain is shifted to D = 0 at the origin
  EXPECT_NEAR(centre->depth, 10.0, 1e-6);
  EXPECT_NEAR(centre->p_N.x(), 0.0, 1e-6);
  EXPECT_NEAR(centre->p_N.y(), 0.0, 1e-6);
}

// Pixel → 3-D ground truth must agree with StereoCamera's projection in both images.
void checkGroundTruth(render::WorldKind kind, const StereoCamera& cam, const Eigen::Vector3d& p_BinN,
                      const Eigen::Vector3d& euler) {
  render::StereoRenderer r(makeWorld(kind), cam);
  const render::StereoRendering out = r.render(p_BinN, euler);
  int checked = 0, agreed = 0;
  double worst_px = 0.0;
  const int w = cam.options().width, h = cam.options().height;
  for (int v = 3; v < h; v += 17) {
    for (int u = 5; u < w; u += 13) {
      const auto pt = out.left.surfaceAt(u, v);
      ASSERT_TRUE(pt.has_value()) << u << "," << v;
      const Eigen::Vector3d p_C = cam.landmarkInCamera(p_BinN, euler, pt->p_N);
      EXPECT_NEAR(p_C.z(), pt->depth, 1e-6 * pt->depth);
      const Eigen::Vector4d z = cam.project(p_C);
      worst_px = std::max(worst_px, (z.head<2>() - Eigen::Vector2d(u, v)).norm());
      if (z(2) < 0.5 || z(2) > w - 1.5) continue;  // not in the right image
      const auto right = out.right.surfaceAt(z(2), z(3));
      ASSERT_TRUE(right.has_value());
      ++checked;
      // Occlusion boundaries may legitimately differ between the two views.
      if ((right->p_N - pt->p_N).norm() < 0.03) ++agreed;
    }
  }
  EXPECT_LT(worst_px, 0.5);
  EXPECT_LT(worst_px, 1e-6);  // in fact exact: same ray, same plane
  ASSERT_GT(checked, 100);
  EXPECT_GT(agreed, 0.97 * checked) << agreed << " of " << checked;
}

TEST(StereoRenderer, GroundTruthMatchesProjectionAerial) {
  const auto [p, e] = aerialPose();
  checkGroundTruth(render::WorldKind::kAerial, StereoCamera(), p, e);
}

TEST(StereoRenderer, GroundTruthMatchesProjectionHall) {
  const auto [p, e] = hallPose();
  checkGroundTruth(render::WorldKind::kHall, euroCCamera(), p, e);
}

TEST(StereoRenderer, HallIsClosedAndWithinItsWalls) {
  render::StereoRenderer r(makeWorld(render::WorldKind::kHall), euroCCamera());
  const auto [p, e] = hallPose();
  const render::StereoRendering out = r.render(p, e);
  EXPECT_EQ(cv::countNonZero(out.left.triangle_ids < 0), 0);  // no sky indoors
  const cv::Mat1f depth = out.left.depthMap();
  double lo = 0, hi = 0;
  cv::minMaxLoc(depth, &lo, &hi);
  EXPECT_GT(lo, 0.05);
  EXPECT_LT(hi, 31.0);  // hall diagonal ≈ 31.8 m
}

int fastCount(const cv::Mat& image) {
  std::vector<cv::KeyPoint> kp;
  cv::FAST(image, kp, 20, true);
  return static_cast<int>(kp.size());
}

TEST(StereoRenderer, LowTextureHasFarFewerFeatures) {
  for (render::WorldKind kind : {render::WorldKind::kAerial, render::WorldKind::kHall}) {
    const StereoCamera cam = kind == render::WorldKind::kAerial ? StereoCamera() : euroCCamera();
    const auto pose = kind == render::WorldKind::kAerial ? aerialPose() : hallPose();
    render::StereoRenderer high(makeWorld(kind, render::TextureVariant::kHigh), cam);
    render::StereoRenderer low(makeWorld(kind, render::TextureVariant::kLow), cam);
    const int n_high = fastCount(high.render(pose.first, pose.second).left.image);
    const int n_low = fastCount(low.render(pose.first, pose.second).left.image);
    EXPECT_GT(n_high, 100);
    EXPECT_GE(n_high, 5 * std::max(1, n_low)) << "high " << n_high << " low " << n_low;
  }
}

TEST(StereoRenderer, ExposureScalesBrightness) {
  const auto [p, e] = aerialPose();
  render::RenderOptions dark;
  dark.effects.exposure = 0.5;
  const cv::Mat nominal =
      render::StereoRenderer(makeWorld(render::WorldKind::kAerial), StereoCamera()).render(p, e).left.image;
  const cv::Mat darker =
      render::StereoRenderer(makeWorld(render::WorldKind::kAerial), StereoCamera(), dark).render(p, e).left.image;
  EXPECT_NEAR(meanOf(darker) / meanOf(nominal), 0.5, 0.02);
}

TEST(StereoRenderer, NoiseHasTheRequestedSigmaAndBlurSmooths) {
  const auto [p, e] = aerialPose();
  auto world = makeWorld(render::WorldKind::kAerial);
  const cv::Mat clean = render::StereoRenderer(world, StereoCamera()).render(p, e).left.image;
  render::RenderOptions noisy;
  noisy.effects.noise_sigma = 4.0;
  const cv::Mat n = render::StereoRenderer(world, StereoCamera(), noisy).render(p, e).left.image;
  cv::Mat diff;
  cv::subtract(n, clean, diff, cv::noArray(), CV_32F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(diff, mean, stddev);
  EXPECT_NEAR(stddev[0], 4.0, 0.3);
  EXPECT_NEAR(mean[0], 0.0, 0.2);

  render::RenderOptions blurred;
  blurred.effects.blur_sigma = 1.5;
  const cv::Mat b = render::StereoRenderer(world, StereoCamera(), blurred).render(p, e).left.image;
  auto sharpness = [](const cv::Mat& img) {
    cv::Mat lap;
    cv::Laplacian(img, lap, CV_32F);
    cv::Scalar m, s;
    cv::meanStdDev(lap, m, s);
    return s[0];
  };
  EXPECT_LT(sharpness(b), 0.5 * sharpness(clean));
}

TEST(StereoRenderer, OptionsLoadFromYaml) {
  auto cfg = ConfigNode::fromString(
      "world: {kind: hall, seed: 4, texel_size: 0.01, texture: {variant: low, tile_size: 256},\n"
      "        hall: {tall_boxes: 3, low_boxes: 2}}\n"
      "render: {far: 50, effects: {exposure: 0.8, noise_sigma: 2}}",
      "scene.yaml");
  ASSERT_TRUE(cfg.ok());
  render::WorldOptions w;
  render::RenderOptions r;
  ASSERT_TRUE(w.load(cfg->child("world")).ok()) << cfg->status().message();
  ASSERT_TRUE(r.load(cfg->child("render")).ok()) << cfg->status().message();
  EXPECT_TRUE(cfg->finish().ok()) << cfg->finish().message();
  EXPECT_EQ(w.kind, render::WorldKind::kHall);
  EXPECT_EQ(w.texture.variant, render::TextureVariant::kLow);
  EXPECT_EQ(w.texture.tile_size, 256);
  EXPECT_EQ(w.hall.tall_boxes, 3);
  EXPECT_DOUBLE_EQ(r.far, 50.0);
  EXPECT_DOUBLE_EQ(r.effects.exposure, 0.8);

  auto bad = ConfigNode::fromString("world: {kind: moon, texture: {tile_size: 1000}}", "b.yaml");
  ASSERT_TRUE(bad.ok());
  render::WorldOptions wb;
  const Status s = wb.load(bad->child("world"));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("b.yaml: world.kind"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace cvslam

namespace cvslam {
namespace {

// Independent re-computation of a pixel's grey level from its ground-truth 3-D point: texture
// coordinates from the material, tile and mirroring from the cell hash, mip level 0 (10 m
// above ground with α = 560: 1.8 cm pixels on 1.5 cm texels).
TEST(StereoRenderer, ShadingMatchesTheMaterialAtTheTruePoint) {
  auto world = test::makeWorld(render::WorldKind::kAerial);
  render::StereoRenderer r(world, StereoCamera());
  const auto [p, e] = test::aerialPose();
  const render::StereoRendering out = r.render(p, e);
  const render::TextureBank& bank = world->textures();
  const double tile = bank.tileSize(), texel = world->texelSize();
  int checked = 0, agreed = 0;
  for (int v = 1; v < 240; v += 7) {
    for (int u = 2; u < 320; u += 5) {
      const int id = out.left.triangle_ids(v, u);
      ASSERT_GE(id, 0);
      const auto pt = out.left.surfaceAt(u, v);
      ASSERT_TRUE(pt.has_value());
      const render::SurfaceMaterial& m =
          world->materials()[static_cast<std::size_t>(world->terrainMaterial())];
      const double s = (m.axis_s.dot(pt->p_N) + m.offset_s) / texel;
      const double t = (m.axis_t.dot(pt->p_N) + m.offset_t) / texel;
      const auto cs = static_cast<int64_t>(std::floor(s / tile));
      const auto ct = static_cast<int64_t>(std::floor(t / tile));
      const uint64_t h = hashCell(cs, ct, m.salt);
      double ls = s - cs * tile, lt = t - ct * tile;
      if ((h >> 40) & 1u) ls = tile - ls;
      if ((h >> 41) & 1u) lt = tile - lt;
      const float expected =
          bank.sample(static_cast<int>(h % static_cast<uint64_t>(bank.tileCount())), 0,
                      static_cast<float>(ls), static_cast<float>(lt)) *
          m.brightness;
      ++checked;
      if (std::abs(expected - out.left.image.at<uint8_t>(v, u)) <= 1.0) ++agreed;
    }
  }
  EXPECT_GT(agreed, 0.98 * checked) << agreed << " of " << checked;
}

}  // namespace
}  // namespace cvslam
