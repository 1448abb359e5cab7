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
  int levels() const { return levels_; }
  /// Mip level `level` (0 = full size) of tile `tile`: CV_8UC1, tileSize() >> level wide.
  const cv::Mat& tile(int tile, int level) const { return mips_[tile][level]; }

  /// Bilinear sample of a tile at a mip level; (s, t) in level-0 texels (texel i covers
  /// [i, i+1)), wrapped into the tile. Returns grey level in [0, 255].
  [[gnu::always_inline]] float sample(int tile, int level, float s, float t) const {
    const Blocked& m = blocked_[static_cast<std::size_t>(tile * levels_ + level)];
    const float x = s * m.scale - 0.5f;
    const float y = t * m.scale - 0.5f;
    // Fast floor (no libm call): truncation corrected for negative values.
    const int xt = static_cast<int>(x), yt = static_cast<int>(y);
    const int xi = xt - (x < static_cast<float>(xt));
    const int yi = yt - (y < static_cast<float>(yt));
    const float ax = x - static_cast<float>(xi);
    const float ay = y - static_cast<float>(yi);
    const int x0 = xi & m.mask, y0 = yi & m.mask;
    const int x1 = (x0 + 1) & m.mask, y1 = (y0 + 1) & m.mask;
    const uint8_t* base = m.texels.data();
    const int* col = m.column_offset.data();
    const int* row = m.row_offset.data();
    const float t00 = base[row[y0] + col[x0]], t10 = base[row[y0] + col[x1]];
    const float t01 = base[row[y1] + col[x0]], t11 = base[row[y1] + col[x1]];
    const float top = t00 + ax * (t10 - t00);
    const float bottom = t01 + ax * (t11 - t01);
    return top + ay * (bottom - top);
  }

 private:
  // A mip level stored in 8×8-texel blocks (one 64-byte cache line each): a pixel row of the
  // image crosses the texture in any direction, and blocks keep its neighbours cached.
  struct Blocked {
    std::vector<uint8_t> texels;
    int size = 0;        // texels per side
    int mask = 0;        // size − 1 (sizes are powers of two)
    int row_stride = 0;  // texels per row of blocks: 8·size
    float scale = 1.0f;  // level-0 texels → this level's texels
    // Offsets of texel (x, y) = row_offset[y] + column_offset[x]: table lookups are cheaper
    // than the shifts and masks of the blocked address.
    std::vector<int> row_offset, column_offset;
  };
  static Blocked block(const cv::Mat& level, int index);

  int tile_size_ = 0;
  int levels_ = 0;
  std::vector<std::vector<cv::Mat>> mips_;  // [tile][level], row-major, for inspection
  std::vector<Blocked> blocked_;            // [tile * levels_ + level], for sampling
};

}  // namespace cvslam
