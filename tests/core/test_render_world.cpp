#include "cvslam/render/world.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "render_test_scenes.h"
#include "test_paths.h"

namespace cvslam {
namespace {

// EuRoC world W (z up) → N: (x, y, z) → (x, −y, −z), see world.h.
std::vector<Eigen::Vector3d> machineHallTrajectoryInN(const std::string& name) {
  std::ifstream in(test::sharedDataDir() + "/euroc/" + name + ".tum");
  std::vector<Eigen::Vector3d> p;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    double t, x, y, z;
    s >> t >> x >> y >> z;
    p.emplace_back(x, -y, -z);
  }
  return p;
}

TEST(World, HallEnclosesEveryMachineHallTrajectoryWithoutCollisions) {
  auto world = test::makeWorld(render::WorldKind::kHall);
  ASSERT_TRUE(world);
  const render::HallWorldOptions& h = world->options().hall;
  ASSERT_FALSE(world->boxes().empty());
  for (const char* seq : {"MH_01_easy", "MH_02_easy", "MH_03_medium"}) {
    const auto traj = machineHallTrajectoryInN(seq);
    ASSERT_GT(traj.size(), 1000u) << seq;
    for (const Eigen::Vector3d& p : traj) {
      ASSERT_TRUE(((p - h.min_N).array() > 1.0).all() && ((h.max_N - p).array() > 0.5).all())
          << seq << " leaves the hall at " << p.transpose();
      for (const render::WorldBox& b : world->boxes())
        ASSERT_FALSE(b.contains(p, 0.2)) << seq << " hits a box at " << p.transpose();
    }
  }
}

TEST(World, AerialTerrainIsAtZeroUnderTheOriginAndBuildingsStandOnIt) {
  auto world = test::makeWorld(render::WorldKind::kAerial);
  ASSERT_TRUE(world && world->terrain());
  const render::Heightfield& t = *world->terrain();
  EXPECT_NEAR(t.downAt(0, 0), 0.0, 1e-12);
  EXPECT_LT(t.maxDown() - t.minDown(), 20.0);
  EXPECT_EQ(world->boxes().size(), 60u);
  for (const render::WorldBox& b : world->boxes()) {
    const Eigen::Vector3d c = 0.5 * (b.lo_N + b.hi_N);
    EXPECT_GT(c.head<2>().norm(), world->options().aerial.clear_radius);
    EXPECT_LT(b.lo_N.z(), t.downAt(c.x(), c.y()));  // top above the ground
    EXPECT_GT(b.hi_N.z(), t.downAt(c.x(), c.y()));  // base buried
  }
}

TEST(World, HeightfieldInterpolatesOnItsTriangles) {
  // Vertex heights 0, 1, 2, 3 at (0,0), (1,0), (0,1), (1,1): the split runs (0,0)–(1,1).
  render::Heightfield h(0, 0, 1.0, 1, 1, {0.0, 1.0, 2.0, 3.0});
  EXPECT_DOUBLE_EQ(h.downAt(0.5, 0.5), 1.5);
  EXPECT_DOUBLE_EQ(h.downAt(0.75, 0.25), 0.75 * 1.0 + 0.25 * 2.0);  // lower: z00 + fx·1 + fy·2
  EXPECT_DOUBLE_EQ(h.downAt(0.25, 0.75), 0.75 * 2.0 + 0.25 * 1.0);  // upper: z00 + fy·2 + fx·1
  EXPECT_DOUBLE_EQ(h.downAt(5.0, 5.0), 3.0);                        // clamped outside
}

TEST(World, SameOptionsSameWorld) {
  auto a = test::makeWorld(render::WorldKind::kHall), b = test::makeWorld(render::WorldKind::kHall);
  ASSERT_EQ(a->triangles().size(), b->triangles().size());
  for (std::size_t i = 0; i < a->triangles().size(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(a->triangles()[i].p_N[k], b->triangles()[i].p_N[k]);
  EXPECT_EQ(cv::norm(a->textures().tile(0, 0), b->textures().tile(0, 0), cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace cvslam
