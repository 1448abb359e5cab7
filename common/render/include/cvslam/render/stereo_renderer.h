#pragma once
// Renders a World as seen by a rectified StereoCamera on a vehicle at pose (p_BinN, euler).
//
// Per camera: the terrain cells inside the view frustum and every other triangle are
// rasterised into an inverse-depth z-buffer (Rasterizer); then every pixel is shaded from
// its triangle's material: texture coordinates are reconstructed perspective-correctly from
// the pixel ray and the inverse depth, the mip level from their screen-space derivatives,
// and the tile from a hash of the texture cell (TextureBank). Exposure scales the radiance
// before 8-bit quantisation, then blur and noise are applied (ImageEffectsOptions).
//
// Pose convention (docs/conventions.md): left camera centre p_CLinN = p_BinN + R_BtoN p_CinB,
// R_NtoCL = R_BtoC R_NtoB(euler); the right camera sits `baseline` along +x_CL.
// Deterministic: the same world, options, pose and frame index give identical images.
// Thread-safe: render() is const and keeps no state, so one renderer may serve many threads.
//
// YAML (section passed to RenderOptions::load):
//   near: 0.05        far: 300        background: 170
//   effects: {exposure: 1.0, blur_sigma: 0.0, noise_sigma: 0.0, noise_seed: 1}

#include <Eigen/Core>

#include <cstdint>
#include <memory>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/core/status.h"
#include "cvslam/render/image_effects.h"
#include "cvslam/render/rendered_image.h"
#include "cvslam/render/world.h"

namespace cvslam {
class ConfigNode;
}  // namespace cvslam

namespace cvslam::render {

struct RenderOptions {
  double near = 0.05;           ///< near clipping distance along z_C [m]
  double far = 300.0;           ///< nothing farther than this is drawn [m]
  int background = 170;         ///< grey level where no surface is seen (sky)
  ImageEffectsOptions effects;  ///< section `effects`

  Status load(const ConfigNode& node);
};

struct StereoRendering {
  RenderedImage left;
  RenderedImage right;
};

class StereoRenderer {
 public:
  StereoRenderer(std::shared_ptr<const World> world, const StereoCamera& camera,
                 const RenderOptions& options = {});

  /// The noise index of the frame taken at t_us: its time in ms. Every program that renders a
  /// simulated flight (cvslam_run in process, cvslam_replay and cvslam_simulate for the agent
  /// processes) indexes frames by time, so that all of them draw the same images.
  static uint64_t frameIndexAt(int64_t t_us) { return static_cast<uint64_t>(t_us / 1000); }

  /// Both images at vehicle pose (p_BinN, euler = [φ θ ψ]); `frame_index` seeds the noise.
  StereoRendering render(const Eigen::Vector3d& p_BinN, const Eigen::Vector3d& euler,
                         uint64_t frame_index = 0) const;

  /// One image from a camera at p_CinN with orientation R_NtoC (used for both stereo sides).
  RenderedImage renderView(const Eigen::Matrix3d& R_NtoC, const Eigen::Vector3d& p_CinN,
                           uint64_t noise_stream) const;

  const World& world() const { return *world_; }
  const StereoCamera& camera() const { return camera_; }
  const RenderOptions& options() const { return options_; }

 private:
  void drawTerrain(const Eigen::Matrix3d& R_NtoC, const Eigen::Vector3d& p_CinN, Rasterizer& raster,
                   std::vector<int>& materials) const;
  void shade(const Eigen::Matrix3d& R_NtoC, const Eigen::Vector3d& p_CinN, const Rasterizer& raster,
             const std::vector<int>& materials, cv::Mat& image) const;

  std::shared_ptr<const World> world_;
  StereoCamera camera_;
  RenderOptions options_;
  PinholeIntrinsics intrinsics_;
};

}  // namespace cvslam::render
