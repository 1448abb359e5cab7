#pragma once
// Internal: geometry builders behind World::create, one per world kind.

#include "cvslam/core/status.h"
#include "cvslam/render/world.h"

namespace cvslam::render::detail {

Status buildAerialWorld(const WorldOptions& options, World& world);
Status buildHallWorld(const WorldOptions& options, World& world);

}  // namespace cvslam::render::detail
