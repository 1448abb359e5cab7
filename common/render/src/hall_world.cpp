// Indoor machine hall for the EuRoC MH trajectories (see world.h for the W → N mapping).

#include "cvslam/core/random.h"
#include "world_builders.h"

namespace cvslam::render::detail {

Status buildHallWorld(const WorldOptions& options, World& world) {
  const HallWorldOptions& o = options.hall;
  Rng rng(mixBits(options.seed ^ 0x4A11ull));
  const Eigen::Vector3d& lo = o.min_N;
  const Eigen::Vector3d& hi = o.max_N;
  // The room itself: a box seen from inside (floor, ceiling, four walls).
  world.addBox(lo, hi, rng.nextU64(), /*inward=*/true);
  const double floor_d = hi.z();
  const double room_height = hi.z() - lo.z();
  // Boxes sink 1 cm into the floor so their bottom faces never fight with it in the z-buffer.
  const double sink = 0.01;

  for (int k = 0; k < o.tall_boxes; ++k) {
    const double along = rng.uniform(0.6, 2.5);
    const double depth = rng.uniform(0.4, o.wall_band);
    const double h = rng.uniform(1.0, std::min(4.0, room_height - 1.0));
    const int wall = static_cast<int>(rng.below(4));
    Eigen::Vector3d b_lo, b_hi;
    // Walls 0/1: at x = lo.x / hi.x (boxes run along y); walls 2/3: at y = lo.y / hi.y.
    const int run_axis = wall < 2 ? 1 : 0;
    const int out_axis = 1 - run_axis;
    const double start = rng.uniform(lo(run_axis), hi(run_axis) - along);
    b_lo(run_axis) = start;
    b_hi(run_axis) = start + along;
    const bool at_low = wall % 2 == 0;
    b_lo(out_axis) = at_low ? lo(out_axis) + 0.05 : hi(out_axis) - 0.05 - depth;
    b_hi(out_axis) = b_lo(out_axis) + depth;
    b_lo.z() = floor_d - h;
    b_hi.z() = floor_d + sink;
    world.addBox(b_lo, b_hi, rng.nextU64());
  }
  for (int k = 0; k < o.low_boxes; ++k) {
    const double w = rng.uniform(0.8, 2.0), d = rng.uniform(0.8, 2.0);
    const double h = rng.uniform(0.15, 0.5);
    const double x = rng.uniform(lo.x() + 0.5, hi.x() - 0.5 - w);
    const double y = rng.uniform(lo.y() + 0.5, hi.y() - 0.5 - d);
    world.addBox({x, y, floor_d - h}, {x + w, y + d, floor_d + sink}, rng.nextU64());
  }
  return Status::Ok();
}

}  // namespace cvslam::render::detail
