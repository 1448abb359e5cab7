#pragma once
// Procedural, seeded texture tiles with mipmaps for the image renderer.
//
// Why tiles: the aerial world is 1 km wide and seen at ~2 cm per pixel; a single texture at
// that resolution would need gigabytes, and evaluating noise per pixel is too slow for the
// frame-time budget. Instead the bank holds `tile_count` different square tiles; every
// surface cell (one tile wide) picks a tile and a mirroring from a hash of its cell index,
// so the pattern does not repeat on a regular grid (it changes at cell seams).
//
// Content (thesis §4.2.4 "low" vs "high" texture): value noise at several wavelengths plus
// opaque disks, rotated rectangles and triangles at five scales (1/8 … 1/128 of the tile).
// Opaque shapes give sharp corners and blobs that SIFT/ORB localise well. `kHigh` is dense
// and contrasted; `kLow` has smooth faint noise and a handful of faint shapes.

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

#include "cvslam/core/status.h"

namespace cvslam {

class ConfigNode;

enum class TextureVariant { kLow, kHigh };

struct TextureOptions {
  TextureVariant variant = TextureVariant::kHigh;  ///< `low` (few, faint features) or `high`
  int tile_size = 1024;  ///< texels per tile side; a power of two (mipmaps wrap by masking)
  int tile_count = 6;    ///< number of distinct tiles
  uint64_t seed = 1;     ///< same seed, same texels (deterministic on every platform)

  /// Keys: variant (low|high), tile_size, tile_count, seed.
  Status load(const ConfigNode& node);
};

class TextureBank {
 public:
  static Expected<TextureBank> create(const TextureOptions& options);

  int tileSize() const { return tile_size_; }
  int tileCount() const { return static_cast<int>(mips_.size()); }
  int levels() const { return static_cast<int>(mips_.front().size()); }
  /// Mip level `level` (0 = full size) of tile `tile`: CV_8UC1, tileSize() >> level wide.
  const cv::Mat& tile(int tile, int level) const { return mips_[tile][level]; }

  /// Bilinear sample of a tile at a mip level; (s, t) in level-0 texels (texel i covers
  /// [i, i+1)), wrapped into the tile. Returns grey level in [0, 255].
  float sample(int tile, int level, float s, float t) const {
    const cv::Mat& m = mips_[tile][level];
    const float scale = 1.0f / static_cast<float>(1 << level);
    const float x = s * scale - 0.5f;
    const float y = t * scale - 0.5f;
    const int mask = m.cols - 1;
    const float fx0 = std::floor(x);
    const float fy0 = std::floor(y);
    const float ax = x - fx0;
    const float ay = y - fy0;
    const int x0 = static_cast<int>(fx0) & mask;
    const int y0 = static_cast<int>(fy0) & mask;
    const int x1 = (x0 + 1) & mask;
    const int y1 = (y0 + 1) & mask;
    const uint8_t* r0 = m.ptr<uint8_t>(y0);
    const uint8_t* r1 = m.ptr<uint8_t>(y1);
    const float top = r0[x0] + ax * (r0[x1] - r0[x0]);
    const float bottom = r1[x0] + ax * (r1[x1] - r1[x0]);
    return top + ay * (bottom - top);
  }

 private:
  int tile_size_ = 0;
  std::vector<std::vector<cv::Mat>> mips_;  // [tile][level]
};

}  // namespace cvslam
