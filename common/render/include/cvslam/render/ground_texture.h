#pragma once
// The true texture of the aerial terrain in ground coordinates: the grey level the renderer
// shades at the terrain point under (x, y) of N, before exposure, quantisation, blur and
// noise. Used as the ground truth of image mosaics (docs/mosaic.md): a mosaic pixel at
// ground position (x, y) should show terrainRadiance(world, x, y).
//
// Same tile lookup as StereoRenderer::shade (TextureBank::cellAt), so the two agree texel for
// texel; `level` selects the mip level (0 = full resolution, 1.5 cm texels by default).

#include "cvslam/render/world.h"

namespace cvslam::render {

/// Terrain grey level (0..255 before exposure) at (x_N, y_N); 0 if the world has no terrain.
/// Buildings are ignored (the terrain under them is returned).
float terrainRadiance(const World& world, double x_N, double y_N, int level = 0);

}  // namespace cvslam::render
