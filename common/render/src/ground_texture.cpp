#include "cvslam/render/ground_texture.h"

#include <algorithm>

namespace cvslam::render {

float terrainRadiance(const World& world, double x_N, double y_N, int level) {
  if (!world.terrain()) return 0.0f;
  const Eigen::Vector3d p_N(x_N, y_N, world.terrain()->downAt(x_N, y_N));
  const SurfaceMaterial& m = world.materials()[static_cast<std::size_t>(world.terrainMaterial())];
  // Texture coordinates in texels, as setupMaterial() of the renderer maps them.
  const double s = (m.axis_s.dot(p_N) + m.offset_s) / world.texelSize();
  const double t = (m.axis_t.dot(p_N) + m.offset_t) / world.texelSize();
  const TextureBank& bank = world.textures();
  const TextureBank::Cell c = bank.cellAt(s, t, m.salt);
  const double ls = std::max(0.0, c.sign_s * s + c.off_s);
  const double lt = std::max(0.0, c.sign_t * t + c.off_t);
  const int lv = std::clamp(level, 0, bank.levels() - 1);
  return bank.sample(c.tile, lv, static_cast<float>(ls), static_cast<float>(lt)) * m.brightness;
}

}  // namespace cvslam::render
