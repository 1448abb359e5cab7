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
}  // namespace cvslam

namespace cvslam::render {

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

  /// One mip level of one tile, stored in 8×8-texel blocks (one 64-byte cache line each):
  /// an image row crosses the texture in any direction, and blocks keep its neighbours cached.
  class Level {
   public:
    /// Bilinear sample; (s, t) ≥ 0 in level-0 texels (texel i covers [i, i+1)), wrapped into
    /// the tile. Returns a grey level in [0, 255].
    float sample(float s, float t) const {
      // Texel centres are at i + 0.5; shifted by one texel so that x, y ≥ 0.5 and truncation
      // is floor (no libm call, no sign test); the −1 is undone by the wrap mask.
      const float x = s * scale_ + 0.5f;
      const float y = t * scale_ + 0.5f;
      const int xi = static_cast<int>(x), yi = static_cast<int>(y);
      const float ax = x - static_cast<float>(xi);
      const float ay = y - static_cast<float>(yi);
      const int x0 = (xi - 1) & mask_, y0 = (yi - 1) & mask_;
      const int x1 = (x0 + 1) & mask_, y1 = (y0 + 1) & mask_;
      const uint8_t* base = texels_.data();
      const int* col = column_offset_.data();
      const int* row = row_offset_.data();
      const float t00 = base[row[y0] + col[x0]], t10 = base[row[y0] + col[x1]];
      const float t01 = base[row[y1] + col[x0]], t11 = base[row[y1] + col[x1]];
      const float top = t00 + ax * (t10 - t00);
      const float bottom = t01 + ax * (t11 - t01);
      return top + ay * (bottom - top);
    }

   private:
    friend class TextureBank;
    std::vector<uint8_t> texels_;
    int mask_ = 0;        // size − 1 (sizes are powers of two)
    float scale_ = 1.0f;  // level-0 texels → this level's texels
    // Offset of texel (x, y) = row_offset_[y] + column_offset_[x]: table lookups are cheaper
    // than the shifts and masks of the blocked address.
    std::vector<int> row_offset_, column_offset_;
  };

  /// Mip level `level` of tile `tile`, for sampling.
  const Level& level(int tile, int level) const {
    return blocked_[static_cast<std::size_t>(tile * levels_ + level)];
  }
  /// Same as level(tile, level).sample(s, t); (s, t) ≥ 0.
  float sample(int tile, int level, float s, float t) const {
    return this->level(tile, level).sample(s, t);
  }

  /// The texture cell (one tile wide) holding surface texture coordinates (s, t) [texels]
  /// of a surface with `salt`: which tile it shows and how the tile is mirrored. Shared by
  /// the renderer's shading and by the true-texture lookups (ground_texture.h), so both see
  /// the same texels.
  struct Cell {
    int tile = 0;
    double s0 = 0.0, t0 = 0.0;  ///< cell extent [s0, s0 + tileSize()) × [t0, t0 + tileSize())
    double sign_s = 1.0, sign_t = 1.0;  ///< tile coordinates ls = sign_s·s + off_s (mirror)
    double off_s = 0.0, off_t = 0.0;
  };
  Cell cellAt(double s, double t, uint64_t salt) const;

 private:
  static Level block(const cv::Mat& level, int index);

  int tile_size_ = 0;
  int levels_ = 0;
  std::vector<std::vector<cv::Mat>> mips_;  // [tile][level], row-major, for inspection
  std::vector<Level> blocked_;              // [tile * levels_ + level], for sampling
};

}  // namespace cvslam::render
