#include "cvslam/render/texture_bank.h"

#include <opencv2/imgproc.hpp>

#include <array>

#include "cvslam/core/random.h"
#include "cvslam/io/config_node.h"

namespace cvslam::render {
namespace {

struct VariantParams {
  std::array<double, 4> noise_amplitude;  // value noise at tile/4, /16, /64, /256 cells
  double shape_density;                   // fraction of the tile area covered per scale
  double shape_contrast;                  // half-range of shape grey levels around 0.5
};

VariantParams paramsFor(TextureVariant v) {
  if (v == TextureVariant::kHigh) return {{0.10, 0.08, 0.06, 0.04}, 0.45, 0.42};
  // Low texture: smooth, faint noise and a few faint shapes (thesis §4.2.4).
  return {{0.05, 0.025, 0.01, 0.0}, 0.015, 0.10};
}

void addValueNoise(Rng& rng, int cells, double amplitude, cv::Mat1f& img) {
  if (amplitude <= 0.0) return;
  cv::Mat1f small(cells, cells);
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c) small(r, c) = static_cast<float>(rng.uniform(-1.0, 1.0));
  cv::Mat1f big;
  cv::resize(small, big, img.size(), 0, 0, cv::INTER_CUBIC);
  img += static_cast<float>(amplitude) * big;
}

// One opaque shape: a disk, a rotated rectangle or a triangle of radius ~r texels.
void addShape(Rng& rng, int n, double r, double contrast, cv::Mat1f& img) {
  const cv::Point2d centre(rng.uniform(0, n), rng.uniform(0, n));
  const double radius = r * rng.uniform(0.5, 1.0);
  const cv::Scalar grey(0.5 + contrast * rng.uniform(-1.0, 1.0));
  // Shapes are drawn with 4 bits of sub-pixel precision so their corners are not snapped.
  constexpr int kShift = 4;
  constexpr double kScale = 1 << kShift;
  const int kind = static_cast<int>(rng.below(3));
  if (kind == 0) {
    cv::circle(img, cv::Point(cvRound(centre.x * kScale), cvRound(centre.y * kScale)),
               cvRound(radius * kScale), grey, cv::FILLED, cv::LINE_AA, kShift);
    return;
  }
  const int corners = kind == 1 ? 4 : 3;
  const double angle0 = rng.uniform(0, 2 * CV_PI);
  const double aspect = rng.uniform(0.4, 1.0);
  std::vector<cv::Point> poly;
  for (int k = 0; k < corners; ++k) {
    const double a = angle0 + 2 * CV_PI * k / corners + (corners == 3 ? rng.uniform(-0.4, 0.4) : 0);
    const double rr = radius * (k % 2 == 0 ? 1.0 : aspect);
    poly.emplace_back(cvRound((centre.x + rr * std::cos(a)) * kScale),
                      cvRound((centre.y + rr * std::sin(a)) * kScale));
  }
  cv::fillConvexPoly(img, poly, grey, cv::LINE_AA, kShift);
}

cv::Mat makeTile(uint64_t seed, int n, const VariantParams& p) {
  Rng rng(seed);
  cv::Mat1f img(n, n, 0.5f);
  const std::array<int, 4> cells = {4, 16, 64, 256};
  for (std::size_t k = 0; k < cells.size(); ++k)
    addValueNoise(rng, std::min(cells[k], n), p.noise_amplitude[k], img);
  // Coarse to fine, so that small shapes sit on top of large ones (blobs within blobs).
  for (int divisor = 8; divisor <= 128; divisor *= 2) {
    const double r = static_cast<double>(n) / divisor;
    const double area = static_cast<double>(n) * n * p.shape_density;
    const int count = static_cast<int>(area / (CV_PI * r * r * 0.5));
    for (int i = 0; i < count; ++i) addShape(rng, n, r, p.shape_contrast, img);
  }
  // A touch of blur keeps edges band-limited, so sampling does not alias at mip level 0.
  cv::GaussianBlur(img, img, cv::Size(0, 0), 0.7);
  cv::Mat out;
  img.convertTo(out, CV_8U, 255.0);
  return out;
}

}  // namespace

Status TextureOptions::load(const ConfigNode& node) {
  node.getEnum("variant", variant,
               {{"low", TextureVariant::kLow}, {"high", TextureVariant::kHigh}});
  node.get("tile_size", tile_size);
  node.get("tile_count", tile_count);
  node.get("seed", seed);
  node.check(tile_size >= 64 && tile_size <= 8192 && (tile_size & (tile_size - 1)) == 0,
             "tile_size", "must be a power of two in [64, 8192]");
  node.check(tile_count >= 1 && tile_count <= 64, "tile_count", "must be in [1, 64]");
  return node.status();
}

TextureBank::Level TextureBank::block(const cv::Mat& level, int index) {
  Level b;
  const int size = level.cols;
  b.mask_ = size - 1;
  b.scale_ = 1.0f / static_cast<float>(1 << index);
  for (int k = 0; k < size; ++k) {
    b.row_offset_.push_back((k >> 3) * 8 * size + ((k & 7) << 3));
    b.column_offset_.push_back(((k >> 3) << 6) + (k & 7));
  }
  b.texels_.resize(static_cast<std::size_t>(size) * size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      b.texels_[static_cast<std::size_t>(b.row_offset_[y] + b.column_offset_[x])] =
          level.at<uint8_t>(y, x);
  return b;
}

Expected<TextureBank> TextureBank::create(const TextureOptions& o) {
  if (o.tile_size < 64 || (o.tile_size & (o.tile_size - 1)) != 0)
    return Status::Error("texture tile_size must be a power of two >= 64");
  if (o.tile_count < 1) return Status::Error("texture tile_count must be >= 1");
  const VariantParams params = paramsFor(o.variant);
  TextureBank bank;
  bank.tile_size_ = o.tile_size;
  for (int t = 0; t < o.tile_count; ++t) {
    std::vector<cv::Mat> levels{makeTile(mixBits(o.seed * 1315423911ull + t), o.tile_size, params)};
    // pyrDown is a proper low-pass before decimation: distant surfaces stay alias-free.
    while (levels.back().cols > 8) {
      cv::Mat down;
      cv::pyrDown(levels.back(), down, cv::Size(), cv::BORDER_REFLECT101);
      levels.push_back(down);
    }
    bank.levels_ = static_cast<int>(levels.size());
    for (std::size_t l = 0; l < levels.size(); ++l)
      bank.blocked_.push_back(block(levels[l], static_cast<int>(l)));
    bank.mips_.push_back(std::move(levels));
  }
  return bank;
}

TextureBank::Cell TextureBank::cellAt(double s, double t, uint64_t salt) const {
  const double tile = tile_size_;
  // floor() without a libm call (the renderer calls this once per cell change).
  auto floor64 = [](double x) {
    const auto i = static_cast<int64_t>(x);
    return i - (x < static_cast<double>(i));
  };
  const int64_t cs = floor64(s / tile), ct = floor64(t / tile);
  const uint64_t h = hashCell(cs, ct, salt);
  Cell c;
  c.tile = static_cast<int>(h % static_cast<uint64_t>(tileCount()));
  c.s0 = static_cast<double>(cs) * tile;
  c.t0 = static_cast<double>(ct) * tile;
  const bool mirror_s = (h >> 40) & 1u, mirror_t = (h >> 41) & 1u;
  c.sign_s = mirror_s ? -1.0 : 1.0;
  c.sign_t = mirror_t ? -1.0 : 1.0;
  c.off_s = mirror_s ? c.s0 + tile : -c.s0;
  c.off_t = mirror_t ? c.t0 + tile : -c.t0;
  return c;
}

}  // namespace cvslam::render
