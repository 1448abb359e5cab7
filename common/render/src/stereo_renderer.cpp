#include "cvslam/render/stereo_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "cvslam/core/random.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/io/config_node.h"

namespace cvslam::render {
namespace {

// Texture mapping of one material in the current camera, in texels:
// s(u, v) = ls·[u v 1] / w + bs, t alike, where w = 1/z_C of the pixel.
struct MaterialSetup {
  Eigen::Vector3d ls, lt;
  double bs = 0.0, bt = 0.0;
  float gain = 1.0f;
  uint64_t salt = 0;
};

MaterialSetup setupMaterial(const SurfaceMaterial& m, const Eigen::Matrix3d& R_NtoC,
                            const Eigen::Vector3d& p_CinN, const PinholeIntrinsics& k, double texel,
                            double exposure) {
  // s = axis_s·(R_CtoN p_C + p_CinN) + offset = (R_NtoC axis_s)·ray(u, v)/w + const.
  auto row = [&](const Eigen::Vector3d& axis) -> Eigen::Vector3d {
    const Eigen::Vector3d g = R_NtoC * axis;
    return Eigen::Vector3d(g.x() / k.fx, g.y() / k.fy,
                           g.z() - g.x() * k.cx / k.fx - g.y() * k.cy / k.fy) /
           texel;
  };
  MaterialSetup s;
  s.ls = row(m.axis_s);
  s.lt = row(m.axis_t);
  s.bs = (m.axis_s.dot(p_CinN) + m.offset_s) / texel;
  s.bt = (m.axis_t.dot(p_CinN) + m.offset_t) / texel;
  s.gain = static_cast<float>(m.brightness * exposure);
  s.salt = m.salt;
  return s;
}

// floor(log2(x)) / 2 for x > 0 from the float exponent: the mip level of a squared footprint.
int halfLog2(float x) {
  uint32_t bits = 0;
  std::memcpy(&bits, &x, sizeof bits);
  const int e = static_cast<int>((bits >> 23) & 0xFF) - 127;
  return e >> 1;  // arithmetic shift: floor division, also for negative exponents
}

// Bounding box in (x, y) of the view frustum (apex to the far plane) inside the slab
// z ∈ [z_lo, z_hi]: its vertices are the frustum's edges clipped to the slab.
bool frustumSlabBounds(const Eigen::Vector3d& apex, const Eigen::Vector3d (&far_corner)[4],
                       double z_lo, double z_hi, Eigen::Vector2d& lo, Eigen::Vector2d& hi) {
  bool any = false;
  lo.setConstant(1e300);
  hi.setConstant(-1e300);
  auto clipSegment = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    double t0 = 0.0, t1 = 1.0;
    const double dz = b.z() - a.z();
    if (std::abs(dz) < 1e-12) {
      if (a.z() < z_lo || a.z() > z_hi) return;
    } else {
      double ta = (z_lo - a.z()) / dz, tb = (z_hi - a.z()) / dz;
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      if (t0 > t1) return;
    }
    for (double t : {t0, t1}) {
      const Eigen::Vector3d p = a + t * (b - a);
      lo = lo.cwiseMin(p.head<2>());
      hi = hi.cwiseMax(p.head<2>());
      any = true;
    }
  };
  for (int k = 0; k < 4; ++k) {
    clipSegment(apex, far_corner[k]);
    clipSegment(far_corner[k], far_corner[(k + 1) % 4]);
  }
  return any;
}

}  // namespace

Status RenderOptions::load(const ConfigNode& node) {
  node.get("near", near);
  node.get("far", far);
  node.get("background", background);
  node.check(near > 0 && far > near, "far", "needs 0 < near < far");
  node.check(background >= 0 && background <= 255, "background", "must be in [0, 255]");
  effects.load(node.child("effects"));
  return node.status();
}

StereoRenderer::StereoRenderer(std::shared_ptr<const World> world, const StereoCamera& camera,
                               const RenderOptions& options)
    : world_(std::move(world)), camera_(camera), options_(options) {
  const StereoCameraOptions& c = camera_.options();
  intrinsics_ = {c.fx, c.fy, c.cx, c.cy, c.width, c.height};
}

StereoRendering StereoRenderer::render(const Eigen::Vector3d& p_BinN, const Eigen::Vector3d& euler,
                                       uint64_t frame_index) const {
  const StereoCameraOptions& c = camera_.options();
  const Eigen::Matrix3d R_NtoB = rotationNavToBody(euler);
  const Eigen::Matrix3d R_NtoC = c.R_BtoC * R_NtoB;
  const Eigen::Vector3d p_CLinN = p_BinN + R_NtoB.transpose() * c.p_CinB;
  const Eigen::Vector3d p_CRinN = p_CLinN + R_NtoC.transpose() * Eigen::Vector3d(c.baseline, 0, 0);
  StereoRendering out;
  out.left = renderView(R_NtoC, p_CLinN, 2 * frame_index);
  out.right = renderView(R_NtoC, p_CRinN, 2 * frame_index + 1);
  return out;
}

RenderedImage StereoRenderer::renderView(const Eigen::Matrix3d& R_NtoC,
                                         const Eigen::Vector3d& p_CinN,
                                         uint64_t noise_stream) const {
  Rasterizer raster(intrinsics_, options_.near, options_.far);
  std::vector<int> materials;  // per triangle id
  drawTerrain(R_NtoC, p_CinN, raster, materials);
  for (const WorldTriangle& tri : world_->triangles()) {
    const int id = raster.draw(R_NtoC * (tri.p_N[0] - p_CinN), R_NtoC * (tri.p_N[1] - p_CinN),
                               R_NtoC * (tri.p_N[2] - p_CinN));
    if (id >= 0) materials.push_back(tri.material);
  }
  RenderedImage out;
  out.image.create(intrinsics_.height, intrinsics_.width, CV_8UC1);
  shade(R_NtoC, p_CinN, raster, materials, out.image);
  applyImageEffects(options_.effects, noise_stream, out.image);
  out.triangle_ids = raster.triangleIds();
  out.planes = raster.planes();
  out.intrinsics = intrinsics_;
  out.R_NtoC = R_NtoC;
  out.p_CinN = p_CinN;
  return out;
}

void StereoRenderer::drawTerrain(const Eigen::Matrix3d& R_NtoC, const Eigen::Vector3d& p_CinN,
                                 Rasterizer& raster, std::vector<int>& materials) const {
  if (!world_->terrain()) return;
  const Heightfield& hf = *world_->terrain();
  const PinholeIntrinsics& k = intrinsics_;
  const Eigen::Matrix3d R_CtoN = R_NtoC.transpose();
  Eigen::Vector3d far_corner[4];
  const double us[4] = {-0.5, k.width - 0.5, k.width - 0.5, -0.5};
  const double vs[4] = {-0.5, -0.5, k.height - 0.5, k.height - 0.5};
  for (int c = 0; c < 4; ++c) {
    const Eigen::Vector3d ray((us[c] - k.cx) / k.fx, (vs[c] - k.cy) / k.fy, 1.0);
    far_corner[c] = p_CinN + R_CtoN * (options_.far * ray);
  }
  Eigen::Vector2d lo, hi;
  if (!frustumSlabBounds(p_CinN, far_corner, hf.minDown(), hf.maxDown(), lo, hi)) return;
  const auto cellIndex = [&](double x, double x0, int n) {
    return std::clamp(static_cast<int>(std::floor((x - x0) / hf.cell())), 0, n - 1);
  };
  const int i0 = cellIndex(lo.x(), hf.x0(), hf.nx()), i1 = cellIndex(hi.x(), hf.x0(), hf.nx());
  const int j0 = cellIndex(lo.y(), hf.y0(), hf.ny()), j1 = cellIndex(hi.y(), hf.y0(), hf.ny());
  if (hi.x() < hf.x0() || hi.y() < hf.y0() || lo.x() > hf.x0() + hf.nx() * hf.cell() ||
      lo.y() > hf.y0() + hf.ny() * hf.cell())
    return;
  // Vertices of the cells in range, in the camera frame (each shared by up to six triangles).
  const int ni = i1 - i0 + 2;
  std::vector<Eigen::Vector3d> v_C(static_cast<std::size_t>(ni * (j1 - j0 + 2)));
  for (int j = j0; j <= j1 + 1; ++j)
    for (int i = i0; i <= i1 + 1; ++i)
      v_C[(j - j0) * ni + (i - i0)] = R_NtoC * (hf.vertex(i, j) - p_CinN);
  const int material = world_->terrainMaterial();
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const Eigen::Vector3d& p00 = v_C[(j - j0) * ni + (i - i0)];
      const Eigen::Vector3d& p10 = v_C[(j - j0) * ni + (i - i0 + 1)];
      const Eigen::Vector3d& p11 = v_C[(j - j0 + 1) * ni + (i - i0 + 1)];
      const Eigen::Vector3d& p01 = v_C[(j - j0 + 1) * ni + (i - i0)];
      // Same split as Heightfield::downAt.
      if (raster.draw(p00, p10, p11) >= 0) materials.push_back(material);
      if (raster.draw(p00, p11, p01) >= 0) materials.push_back(material);
    }
  }
}

void StereoRenderer::shade(const Eigen::Matrix3d& R_NtoC, const Eigen::Vector3d& p_CinN,
                           const Rasterizer& raster, const std::vector<int>& materials,
                           cv::Mat& image) const {
  const TextureBank& bank = world_->textures();
  const double exposure = options_.effects.exposure;
  std::vector<MaterialSetup> setups;
  setups.reserve(world_->materials().size());
  for (const SurfaceMaterial& m : world_->materials())
    setups.push_back(setupMaterial(m, R_NtoC, p_CinN, intrinsics_, world_->texelSize(), exposure));
  const auto background = cv::saturate_cast<uint8_t>(options_.background * exposure);
  const double tile = bank.tileSize();
  const int max_level = bank.levels() - 1;
  const std::vector<Eigen::Vector3d>& planes = raster.planes();

  for (int j = 0; j < image.rows; ++j) {
    const float* wrow = raster.inverseDepth().ptr<float>(j);
    const int* idrow = raster.triangleIds().ptr<int>(j);
    uint8_t* out = image.ptr<uint8_t>(j);
    // The texture cell of the previous pixel (neighbours almost always share it): its
    // extent [s0, s0 + tile) × [t0, t0 + tile), tile, and the map to tile coordinates
    // ls = sign_s·s + off_s (the sign mirrors the tile).
    // NaN: no cell yet (every comparison with it fails).
    double cell_s0 = std::numeric_limits<double>::quiet_NaN(), cell_t0 = cell_s0;
    double sign_s = 1.0, sign_t = 1.0, off_s = 0.0, off_t = 0.0;
    int last_material = -1, tile_index = 0, last_tile = -1, last_level = -1;
    const TextureBank::Level* texture = nullptr;
    int i = 0;
    while (i < image.cols) {
      // A run of pixels on one triangle shares its material, plane and texture mapping.
      const int id = idrow[i];
      int end = i + 1;
      while (end < image.cols && idrow[end] == id) ++end;
      if (id < 0) {
        std::memset(out + i, background, static_cast<std::size_t>(end - i));
        i = end;
        continue;
      }
      const int m = materials[static_cast<std::size_t>(id)];
      const MaterialSetup& S = setups[static_cast<std::size_t>(m)];
      const Eigen::Vector3d& P = planes[static_cast<std::size_t>(id)];
      if (m != last_material) {
        cell_s0 = cell_t0 = std::numeric_limits<double>::quiet_NaN();
        last_material = m;
      }
      // Numerators of s and t are affine in u: step them along the run.
      double ns = S.ls.x() * i + S.ls.y() * j + S.ls.z();
      double nt = S.lt.x() * i + S.lt.y() * j + S.lt.z();
      int level = 0;
      for (const int run_start = i; i < end; ++i, ns += S.ls.x(), nt += S.lt.x()) {
        const double inv_w = 1.0 / wrow[i];
        const double s = ns * inv_w + S.bs;
        const double t = nt * inv_w + S.bt;
        if (i == run_start || (i & 7) == 0) {
          // Mip level from the screen-space derivatives of (s, t), every 8 pixels: the
          // footprint changes slowly along a run.
          const double ds_du = (S.ls.x() - ns * inv_w * P.x()) * inv_w;
          const double ds_dv = (S.ls.y() - ns * inv_w * P.y()) * inv_w;
          const double dt_du = (S.lt.x() - nt * inv_w * P.x()) * inv_w;
          const double dt_dv = (S.lt.y() - nt * inv_w * P.y()) * inv_w;
          const double rho2 =
              std::max(ds_du * ds_du + dt_du * dt_du, ds_dv * ds_dv + dt_dv * dt_dv);
          level = std::clamp(halfLog2(static_cast<float>(rho2) + 1e-30f), 0, max_level);
        }
        if (!(s >= cell_s0 && s < cell_s0 + tile && t >= cell_t0 && t < cell_t0 + tile)) {
          const TextureBank::Cell c = bank.cellAt(s, t, S.salt);
          tile_index = c.tile;
          cell_s0 = c.s0;
          cell_t0 = c.t0;
          sign_s = c.sign_s;
          sign_t = c.sign_t;
          off_s = c.off_s;
          off_t = c.off_t;
        }
        // Clamped at 0: rounding at a cell edge must not give a (tiny) negative coordinate.
        const double ls = std::max(0.0, sign_s * s + off_s);
        const double lt = std::max(0.0, sign_t * t + off_t);
        if (tile_index != last_tile || level != last_level) {
          texture = &bank.level(tile_index, level);
          last_tile = tile_index;
          last_level = level;
        }
        const float value =
            texture->sample(static_cast<float>(ls), static_cast<float>(lt)) * S.gain;
        out[i] = cv::saturate_cast<uint8_t>(value);
      }
    }
  }
}

}  // namespace cvslam::render
