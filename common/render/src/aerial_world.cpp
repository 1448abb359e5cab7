// Aerial world: rolling heightfield terrain with box buildings (see world.h).

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "cvslam/core/random.h"
#include "world_builders.h"

namespace cvslam::render::detail {
namespace {

// Smooth random field over an (n+1)×(n+1) vertex grid with about `waves` periods across it.
cv::Mat1d smoothField(Rng& rng, int n, double waves) {
  const int cells = std::max(2, static_cast<int>(std::ceil(waves)) + 1);
  cv::Mat1d small(cells, cells);
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c) small(r, c) = rng.uniform(-1.0, 1.0);
  cv::Mat1d big;
  cv::resize(small, big, cv::Size(n + 1, n + 1), 0, 0, cv::INTER_CUBIC);
  return big;
}

}  // namespace

Status buildAerialWorld(const WorldOptions& options, World& world) {
  const AerialWorldOptions& o = options.aerial;
  Rng rng(mixBits(options.seed ^ 0xAE121A1ull));
  const int n = std::max(1, static_cast<int>(std::lround(o.size / o.cell)));
  const double half = 0.5 * n * o.cell;

  // Three octaves: the main undulation, hills, and small bumps.
  cv::Mat1d height(n + 1, n + 1, 0.0);
  const double waves = o.size / o.wavelength;
  height += o.amplitude * smoothField(rng, n, waves);
  height += (o.amplitude / 3.0) * smoothField(rng, n, 2.5 * waves);
  height += (o.amplitude / 10.0) * smoothField(rng, n, 6.0 * waves);
  std::vector<double> down(static_cast<std::size_t>((n + 1) * (n + 1)));
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) down[j * (n + 1) + i] = -height(j, i);
  // Shift so that the ground is exactly at D = 0 under the origin (take-off point).
  const double d0 = Heightfield(-half, -half, o.cell, n, n, down).downAt(0.0, 0.0);
  for (double& d : down) d -= d0;
  Heightfield terrain(-half, -half, o.cell, n, n, std::move(down));

  SurfaceMaterial ground;
  ground.brightness = 0.9f;
  ground.salt = rng.nextU64();
  world.setTerrain(terrain, world.addMaterial(ground));

  for (int b = 0; b < o.buildings; ++b) {
    const double w = rng.uniform(o.building_size(0), o.building_size(1));
    const double d = rng.uniform(o.building_size(0), o.building_size(1));
    const double h = rng.uniform(o.building_height(0), o.building_height(1));
    const double margin = 0.5 * std::max(w, d) + 1.0;
    if (half <= margin) break;
    Eigen::Vector2d c;
    int tries = 0;
    do {
      c = {rng.uniform(-half + margin, half - margin), rng.uniform(-half + margin, half - margin)};
    } while (c.norm() < o.clear_radius + margin && ++tries < 100);
    if (tries >= 100) continue;
    // Stand on the highest ground under the footprint; bury down to the lowest.
    double high = 1e9, low = -1e9;
    for (double fx : {-0.5, 0.0, 0.5})
      for (double fy : {-0.5, 0.0, 0.5}) {
        const double z = terrain.downAt(c.x() + fx * w, c.y() + fy * d);
        high = std::min(high, z);
        low = std::max(low, z);
      }
    world.addBox({c.x() - 0.5 * w, c.y() - 0.5 * d, high - h},
                 {c.x() + 0.5 * w, c.y() + 0.5 * d, low + 0.5}, rng.nextU64());
  }
  return Status::Ok();
}

}  // namespace cvslam::render::detail
