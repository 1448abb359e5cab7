#include "cvslam/render/world.h"

#include <Eigen/Geometry>

#include "cvslam/io/config_node.h"
#include "cvslam/core/random.h"
#include "world_builders.h"

namespace cvslam::render {

Status AerialWorldOptions::load(const ConfigNode& node) {
  node.get("size", size);
  node.get("cell", cell);
  node.get("amplitude", amplitude);
  node.get("wavelength", wavelength);
  node.get("buildings", buildings);
  node.get("building_size", building_size);
  node.get("building_height", building_height);
  node.get("clear_radius", clear_radius);
  node.check(size > 0 && cell > 0 && size / cell <= 4096, "size",
             "needs size > 0 and size/cell <= 4096");
  node.check(wavelength > cell, "wavelength", "must exceed the grid cell");
  node.check(amplitude >= 0, "amplitude", "must be >= 0");
  node.check(buildings >= 0, "buildings", "must be >= 0");
  node.check(building_size(0) > 0 && building_size(1) >= building_size(0), "building_size",
             "must be [min, max] with 0 < min <= max");
  node.check(building_height(0) > 0 && building_height(1) >= building_height(0), "building_height",
             "must be [min, max] with 0 < min <= max");
  return node.status();
}

Status HallWorldOptions::load(const ConfigNode& node) {
  node.get("min_N", min_N);
  node.get("max_N", max_N);
  node.get("tall_boxes", tall_boxes);
  node.get("low_boxes", low_boxes);
  node.get("wall_band", wall_band);
  node.check(((max_N - min_N).array() > 2.0).all(), "max_N", "hall must be > 2 m along every axis");
  node.check(tall_boxes >= 0 && low_boxes >= 0, "tall_boxes", "box counts must be >= 0");
  node.check(wall_band > 0.2, "wall_band", "must be > 0.2 m");
  return node.status();
}

Status WorldOptions::load(const ConfigNode& node) {
  node.getEnum("kind", kind, {{"aerial", WorldKind::kAerial}, {"hall", WorldKind::kHall}});
  node.get("seed", seed);
  node.get("texel_size", texel_size);
  node.check(texel_size >= 0, "texel_size", "must be >= 0 (0 = default of the kind)");
  texture.load(node.child("texture"));
  aerial.load(node.child("aerial"));
  hall.load(node.child("hall"));
  return node.status();
}

double WorldOptions::effectiveTexelSize() const {
  if (texel_size > 0) return texel_size;
  // Aerial: ~1.8 cm pixel footprint at 10 m with f = 560. Hall: ~1 cm at 4.5 m with f = 458, so
  // the largest shapes (128 texels) are ~1.3 m posters and the smallest ~8 cm.
  return kind == WorldKind::kAerial ? 0.015 : 0.01;
}

float sunShading(const Eigen::Vector3d& n_N) {
  // Towards the sun: up, from the south-west (N frame: x north, y east, z down).
  const Eigen::Vector3d to_sun = Eigen::Vector3d(-0.5, -0.4, -0.77).normalized();
  return static_cast<float>(0.55 + 0.45 * std::max(0.0, n_N.dot(to_sun)));
}

int World::addMaterial(const SurfaceMaterial& m) {
  materials_.push_back(m);
  return static_cast<int>(materials_.size()) - 1;
}

void World::setTerrain(Heightfield terrain, int material) {
  terrain_ = std::move(terrain);
  terrain_material_ = material;
}

void World::addBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, uint64_t salt,
                   bool inward) {
  if (!inward) boxes_.push_back({lo, hi});
  Rng rng(salt);
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n(axis) = side == 0 ? -1.0 : 1.0;
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      SurfaceMaterial m;
      // Texture axes are the two world axes in the face; vertical faces keep "down" as t.
      const int s_axis = axis == 2 ? 0 : (a == 2 ? b : a);
      const int t_axis = axis == 2 ? 1 : 2;
      m.axis_s = Eigen::Vector3d::Unit(s_axis);
      m.axis_t = Eigen::Vector3d::Unit(t_axis);
      // Random offsets so that faces do not all start a texture tile at the world origin.
      m.offset_s = rng.uniform(0.0, 1000.0);
      m.offset_t = rng.uniform(0.0, 1000.0);
      m.brightness = sunShading(inward ? Eigen::Vector3d(-n) : n);
      m.salt = rng.nextU64();
      const int mat = addMaterial(m);
      const double c = side == 0 ? lo(axis) : hi(axis);
      auto corner = [&](double u, double v) {
        Eigen::Vector3d p;
        p(axis) = c;
        p(a) = u;
        p(b) = v;
        return p;
      };
      const Eigen::Vector3d p00 = corner(lo(a), lo(b)), p10 = corner(hi(a), lo(b)),
                            p11 = corner(hi(a), hi(b)), p01 = corner(lo(a), hi(b));
      triangles_.push_back({{p00, p10, p11}, mat});
      triangles_.push_back({{p00, p11, p01}, mat});
    }
  }
}

Expected<std::shared_ptr<const World>> World::create(const WorldOptions& options) {
  auto world = std::make_shared<World>();
  world->options_ = options;
  world->texel_size_ = options.effectiveTexelSize();
  auto bank = TextureBank::create(options.texture);
  if (!bank.ok()) return bank.status();
  world->textures_ = std::make_shared<const TextureBank>(std::move(*bank));
  const Status built = options.kind == WorldKind::kAerial
                           ? detail::buildAerialWorld(options, *world)
                           : detail::buildHallWorld(options, *world);
  if (!built.ok()) return built;
  return std::shared_ptr<const World>(std::move(world));
}

}  // namespace cvslam::render
