#pragma once
// A textured 3-D world for the image renderer, in the navigation frame N (NED, z down).
//
// Two kinds:
//  - `aerial`: a square heightfield terrain centred on the origin (ground near D = 0, exactly
//    0 at the origin) with box buildings standing on it, for downward-looking cameras
//    (thesis Table 5.6: ~10 m above ground).
//  - `hall`: an indoor machine hall (floor, four walls, ceiling) with boxes, sized for the
//    EuRoC MH trajectories. EuRoC's world frame W is z-up; we use N = R_WtoN W with
//    R_WtoN = diag(1, −1, −1) (x north, y → west becomes east with a sign flip, z up → down),
//    so a EuRoC position (x, y, z) is (x, −y, −z) in N. The default hall spans
//    x ∈ [−7, 19], y ∈ [−4.5, 11.5], z ∈ [−2, 8] in W: 26 m × 16 m × 10 m, enclosing all MH
//    trajectories with > 1 m to spare; tall boxes stand only along the walls, low ones
//    (≤ 0.6 m, below every MH trajectory) anywhere on the floor.
//
// YAML (section passed to WorldOptions::load):
//   kind: aerial            # aerial | hall
//   seed: 1                 # geometry and texture seed
//   texel_size: 0           # metres per texel; 0 = kind default (aerial 0.015, hall 0.01)
//   texture: {variant: high, tile_size: 1024, tile_count: 6}
//   aerial: {size: 1000, cell: 4, amplitude: 3, wavelength: 150,
//            buildings: 60, building_size: [4, 20], building_height: [2, 6], clear_radius: 30}
//   hall: {min_N: [-7, -11.5, -8], max_N: [19, 4.5, 2], tall_boxes: 24, low_boxes: 20,
//          wall_band: 1.2}

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/render/heightfield.h"
#include "cvslam/render/texture_bank.h"

namespace cvslam {
class ConfigNode;
}  // namespace cvslam

namespace cvslam::render {

enum class WorldKind { kAerial, kHall };

struct AerialWorldOptions {
  double size = 1000.0;                       ///< terrain side [m], centred on the origin
  double cell = 4.0;                          ///< heightfield grid spacing [m]
  double amplitude = 3.0;                     ///< height of the main terrain undulation [m]
  double wavelength = 150.0;                  ///< wavelength of the main undulation [m]
  int buildings = 60;                         ///< number of box buildings
  Eigen::Vector2d building_size{4.0, 20.0};   ///< footprint side range [m]
  Eigen::Vector2d building_height{2.0, 6.0};  ///< height above ground range [m]
  double clear_radius = 30.0;  ///< no building closer than this to the origin (take-off) [m]
  Status load(const ConfigNode& node);
};

struct HallWorldOptions {
  Eigen::Vector3d min_N{-7.0, -11.5, -8.0};  ///< hall corner (N frame; D min = ceiling) [m]
  Eigen::Vector3d max_N{19.0, 4.5, 2.0};     ///< opposite corner (D max = floor) [m]
  int tall_boxes = 24;                       ///< machines/shelves standing along the walls
  int low_boxes = 20;                        ///< pallets (≤ 0.6 m) anywhere on the floor
  double wall_band = 1.2;                    ///< tall boxes stay within this of a wall [m]
  Status load(const ConfigNode& node);
};

struct WorldOptions {
  WorldKind kind = WorldKind::kAerial;  ///< aerial | hall
  uint64_t seed = 1;                    ///< geometry seed (texture has its own)
  double texel_size = 0.0;              ///< metres per texel; 0: aerial 0.015, hall 0.01
  TextureOptions texture;               ///< section `texture`
  AerialWorldOptions aerial;            ///< section `aerial`
  HallWorldOptions hall;                ///< section `hall`

  Status load(const ConfigNode& node);
  double effectiveTexelSize() const;
};

/// How a planar face is textured: texture coordinates in metres are
/// s = axis_s·p_N + offset_s, t = axis_t·p_N + offset_t; `salt` decorrelates the tile choice
/// between faces; `brightness` is the face's fixed shading (a sun from above-south-west).
struct SurfaceMaterial {
  Eigen::Vector3d axis_s = Eigen::Vector3d::UnitX();
  Eigen::Vector3d axis_t = Eigen::Vector3d::UnitY();
  double offset_s = 0.0;
  double offset_t = 0.0;
  float brightness = 1.0f;
  uint64_t salt = 0;
};

/// An axis-aligned solid box in N (buildings, machines, pallets), for collision checks.
struct WorldBox {
  Eigen::Vector3d lo_N, hi_N;
  bool contains(const Eigen::Vector3d& p_N, double margin = 0.0) const {
    return ((p_N.array() > lo_N.array() - margin) && (p_N.array() < hi_N.array() + margin)).all();
  }
};

struct WorldTriangle {
  std::array<Eigen::Vector3d, 3> p_N;  ///< vertices in N [m]
  int material = 0;                    ///< index into World::materials()
};

class World {
 public:
  /// Builds geometry and textures (deterministic for the same options).
  static Expected<std::shared_ptr<const World>> create(const WorldOptions& options);

  const WorldOptions& options() const { return options_; }
  const TextureBank& textures() const { return *textures_; }
  double texelSize() const { return texel_size_; }
  /// Terrain (aerial only) and the material of its triangles.
  const std::optional<Heightfield>& terrain() const { return terrain_; }
  int terrainMaterial() const { return terrain_material_; }
  /// Every triangle that is not terrain (buildings, hall surfaces and boxes).
  const std::vector<WorldTriangle>& triangles() const { return triangles_; }
  const std::vector<SurfaceMaterial>& materials() const { return materials_; }
  /// Solid boxes (not the hall's room, which is seen from inside).
  const std::vector<WorldBox>& boxes() const { return boxes_; }

  // Construction helpers used by the world builders.
  int addMaterial(const SurfaceMaterial& m);
  /// Axis-aligned box [lo, hi] in N, all six faces textured and shaded; `salt` for texture.
  void addBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, uint64_t salt,
              bool inward = false);
  void setTerrain(Heightfield terrain, int material);

 private:
  WorldOptions options_;
  double texel_size_ = 0.0;
  std::shared_ptr<const TextureBank> textures_;
  std::optional<Heightfield> terrain_;
  int terrain_material_ = 0;
  std::vector<WorldTriangle> triangles_;
  std::vector<SurfaceMaterial> materials_;
  std::vector<WorldBox> boxes_;
};

/// Fixed face shading: brightness of a surface with outward normal n_N under our sun.
float sunShading(const Eigen::Vector3d& n_N);

}  // namespace cvslam::render
