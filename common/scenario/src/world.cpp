#include "cvslam/scenario/world.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cvslam/io/config_node.h"

namespace cvslam::sim {

Status WorldOptions::load(const ConfigNode& node) {
  node.get("ground_z", ground_z);
  node.get("relief_amplitude", relief_amplitude);
  node.get("relief_wavelength", relief_wavelength);
  node.get("landmark_density", landmark_density);
  node.get("landmark_height_jitter", landmark_height_jitter);
  node.get("margin", margin);
  node.check(relief_amplitude >= 0.0, "relief_amplitude", "must be >= 0");
  node.check(relief_wavelength > 0.0, "relief_wavelength", "must be > 0");
  node.check(landmark_density > 0.0 && landmark_density <= 100.0, "landmark_density",
             "must be in (0, 100] per m²");
  node.check(landmark_height_jitter >= 0.0, "landmark_height_jitter", "must be >= 0");
  node.check(margin >= 0.0, "margin", "must be >= 0");
  return node.status();
}

Terrain::Terrain(const WorldOptions& o, Rng& rng) : ground_z_(o.ground_z) {
  const double fractions[4] = {0.5, 0.25, 0.15, 0.1};
  const double divisors[4] = {1.0, 2.0, 3.0, 5.0};
  for (int w = 0; w < 4; ++w) {
    const double dir = rng.uniform(0.0, 2.0 * M_PI);
    const double k = 2.0 * M_PI * divisors[w] / o.relief_wavelength;
    k_.row(w) << k * std::cos(dir), k * std::sin(dir);
    amplitude_(w) = o.relief_amplitude * fractions[w];
    phase_(w) = rng.uniform(0.0, 2.0 * M_PI);
  }
}

double Terrain::groundZ(double x, double y) const {
  double h = 0.0;
  for (int w = 0; w < 4; ++w)
    h += amplitude_(w) * std::sin(k_(w, 0) * x + k_(w, 1) * y + phase_(w));
  return ground_z_ - h;
}

int World::cellX(double x) const {
  return std::clamp(static_cast<int>(std::floor((x - region_.min().x()) / cell_)), 0, nx_ - 1);
}

int World::cellY(double y) const {
  return std::clamp(static_cast<int>(std::floor((y - region_.min().y()) / cell_)), 0, ny_ - 1);
}

Expected<World> World::generate(const WorldOptions& o, const Eigen::AlignedBox2d& region,
                                uint64_t seed) {
  if (region.isEmpty()) return Status::Error("world: empty region");
  const Eigen::Vector2d size = region.sizes();
  const double count_d = std::round(o.landmark_density * size.x() * size.y());
  if (count_d > 2e7) {
    return Status::Error("world: " + std::to_string(static_cast<long long>(count_d)) +
                         " landmarks is too many (lower landmark_density or the region)");
  }
  World world;
  Rng rng(seed);
  world.terrain_ = Terrain(o, rng);
  world.region_ = region;
  // About 16 landmarks per grid cell.
  world.cell_ = std::clamp(std::sqrt(16.0 / o.landmark_density), 1.0, 100.0);
  world.nx_ = std::max(1, static_cast<int>(std::ceil(size.x() / world.cell_)));
  world.ny_ = std::max(1, static_cast<int>(std::ceil(size.y() / world.cell_)));

  const std::size_t count = static_cast<std::size_t>(count_d);
  std::vector<Landmark> raw(count);
  std::vector<uint32_t> cell_of(count);
  std::vector<uint32_t> cell_count(static_cast<std::size_t>(world.nx_ * world.ny_) + 1, 0);
  world.min_z_ = std::numeric_limits<double>::infinity();
  world.max_z_ = -std::numeric_limits<double>::infinity();
  for (std::size_t n = 0; n < count; ++n) {
    const double x = rng.uniform(region.min().x(), region.max().x());
    const double y = rng.uniform(region.min().y(), region.max().y());
    const double z = world.terrain_.groundZ(x, y) - rng.uniform(0.0, o.landmark_height_jitter);
    raw[n].p_LinN = {x, y, z};
    cell_of[n] = static_cast<uint32_t>(world.cellY(y) * world.nx_ + world.cellX(x));
    ++cell_count[cell_of[n] + 1];
    world.min_z_ = std::min(world.min_z_, z);
    world.max_z_ = std::max(world.max_z_, z);
  }
  if (count == 0) world.min_z_ = world.max_z_ = o.ground_z;
  // Counting sort by cell; ids follow the sorted order.
  for (std::size_t c = 1; c < cell_count.size(); ++c) cell_count[c] += cell_count[c - 1];
  world.cell_start_ = cell_count;
  world.landmarks_.resize(count);
  std::vector<uint32_t> next(cell_count.begin(), cell_count.end() - 1);
  for (std::size_t n = 0; n < count; ++n) world.landmarks_[next[cell_of[n]]++] = raw[n];
  for (std::size_t n = 0; n < count; ++n) world.landmarks_[n].id = static_cast<uint32_t>(n);
  return world;
}

}  // namespace cvslam::sim
