#include "cvslam/mosaic/mosaic_builder.h"

#include <Eigen/LU>
#include <Eigen/QR>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>

#include "cvslam/io/config_node.h"

namespace cvslam::mosaic {
namespace {

Eigen::Matrix3d translation(double dx, double dy) {
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  T(0, 2) = dx;
  T(1, 2) = dy;
  return T;
}

std::array<Eigen::Vector2d, 4> corners(const cv::Mat& image) {
  const double w = image.cols - 1, h = image.rows - 1;
  return {Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0), Eigen::Vector2d(w, h),
          Eigen::Vector2d(0, h)};
}

// Bounding box (in mosaic pixels, clipped to the grid) of the image warped by H, grown by
// `grow` pixels.
cv::Rect warpedBox(const cv::Mat& image, const Eigen::Matrix3d& H, double grow, cv::Size grid) {
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const Eigen::Vector2d& c : corners(image)) {
    const Eigen::Vector2d p = applyHomography(H, c);
    x0 = std::min(x0, p.x());
    y0 = std::min(y0, p.y());
    x1 = std::max(x1, p.x());
    y1 = std::max(y1, p.y());
  }
  const cv::Rect box(
      cv::Point(static_cast<int>(std::floor(x0 - grow)), static_cast<int>(std::floor(y0 - grow))),
      cv::Point(static_cast<int>(std::ceil(x1 + grow)) + 1,
                static_cast<int>(std::ceil(y1 + grow)) + 1));
  return box & cv::Rect(cv::Point(0, 0), grid);
}

cv::Matx33d toMatx(const Eigen::Matrix3d& H) {
  cv::Matx33d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = H(r, c);
  return m;
}

}  // namespace

Status MosaicOptions::load(const ConfigNode& node) {
  node.get("gsd", gsd);
  node.get("margin", margin);
  node.get("ground_down", ground_down);
  node.get("register", register_frames);
  node.get("min_overlap", min_overlap);
  node.get("max_neighbours", max_neighbours);
  node.get("max_links_per_pair", max_links_per_pair);
  node.get("max_correction_px", max_correction_px);
  node.get("feather_px", feather_px);
  node.get("max_megapixels", max_megapixels);
  node.get("min_ground_points", min_ground_points);
  node.get("min_ground_spread", min_ground_spread);
  adjustment.load(node.child("adjustment"));
  node.check(gsd > 0.0, "gsd", "must be > 0");
  node.check(margin >= 0.0, "margin", "must be ≥ 0");
  node.check(min_overlap >= 0.0 && min_overlap <= 1.0, "min_overlap", "must be in [0, 1]");
  node.check(max_neighbours >= 1, "max_neighbours", "must be ≥ 1");
  node.check(max_links_per_pair >= 1, "max_links_per_pair", "must be ≥ 1");
  node.check(max_correction_px > 0.0, "max_correction_px", "must be > 0");
  node.check(feather_px > 0.0, "feather_px", "must be > 0");
  node.check(max_megapixels > 0.0, "max_megapixels", "must be > 0");
  node.check(min_ground_points >= 3, "min_ground_points", "must be ≥ 3");
  node.check(min_ground_spread >= 0.0, "min_ground_spread", "must be ≥ 0");
  return node.status();
}

Eigen::Matrix3d MosaicGrid::groundToPixel() const {
  Eigen::Matrix3d M;
  M << 0, 1 / gsd, -y_min / gsd, -1 / gsd, 0, x_max / gsd, 0, 0, 1;
  return M;
}

Eigen::Vector2d MosaicGrid::toPixel(const Eigen::Vector2d& xy) const {
  return {(xy.y() - y_min) / gsd, (x_max - xy.x()) / gsd};
}

Eigen::Vector2d MosaicGrid::toGround(const Eigen::Vector2d& px) const {
  return {x_max - px.y() * gsd, y_min + px.x() * gsd};
}

Eigen::Matrix3d imageToGround(const MosaicFrame& f, double ground_down) {
  // Ground point (x, y, a·x + b·y + c) in the camera: R_NtoC (X − p_CinN) = R B [x y 1]ᵀ.
  const Eigen::Vector3d plane = f.ground_plane.value_or(Eigen::Vector3d(0.0, 0.0, ground_down));
  Eigen::Matrix3d B;
  B.col(0) = Eigen::Vector3d::UnitX() + plane(0) * Eigen::Vector3d::UnitZ();
  B.col(1) = Eigen::Vector3d::UnitY() + plane(1) * Eigen::Vector3d::UnitZ();
  B.col(2) = plane(2) * Eigen::Vector3d::UnitZ() - f.p_CinN;
  const Eigen::Matrix3d ground_to_image = f.K * f.R_NtoC * B;
  return ground_to_image.inverse();
}

std::optional<Eigen::Vector3d> groundPlaneFromPoints(const MosaicFrame& f,
                                                     const std::vector<Eigen::Vector3d>& points,
                                                     int min_points, double min_spread) {
  std::vector<Eigen::Vector3d> seen;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d c = f.R_NtoC * (p - f.p_CinN);
    if (c.z() <= 0.0) continue;
    const Eigen::Vector3d u = f.K * c;
    const double x = u.x() / u.z(), y = u.y() / u.z();
    if (x >= 0 && y >= 0 && x <= f.image.cols - 1 && y <= f.image.rows - 1) seen.push_back(p);
  }
  if (static_cast<int>(seen.size()) < std::max(1, min_points / 2)) return std::nullopt;
  std::vector<double> downs;
  Eigen::Vector2d lo = seen.front().head<2>(), hi = lo;
  for (const Eigen::Vector3d& p : seen) {
    downs.push_back(p.z());
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  std::nth_element(downs.begin(), downs.begin() + static_cast<long>(downs.size() / 2), downs.end());
  const Eigen::Vector3d level(0.0, 0.0, downs[downs.size() / 2]);
  if (static_cast<int>(seen.size()) < min_points || (hi - lo).minCoeff() < min_spread) return level;
  Eigen::MatrixXd A(static_cast<Eigen::Index>(seen.size()), 3);
  Eigen::VectorXd z(A.rows());
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    const Eigen::Vector3d& p = seen[static_cast<std::size_t>(i)];
    A.row(i) << p.x(), p.y(), 1.0;
    z(i) = p.z();
  }
  const Eigen::Vector3d plane = A.colPivHouseholderQr().solve(z);
  return plane.allFinite() ? plane : level;
}

MosaicBuilder::MosaicBuilder(const MosaicGrid& grid, const MosaicOptions& mosaic,
                             const RegistrationOptions& registration,
                             const PhotometricOptions& photometric)
    : grid_(grid), o_(mosaic), reg_(registration), photo_(photometric) {
  sum_ = cv::Mat(grid.rows, grid.cols, CV_32F, cv::Scalar(0));
  weight_ = cv::Mat(grid.rows, grid.cols, CV_32F, cv::Scalar(0));
}

Expected<MosaicGrid> MosaicBuilder::gridCovering(const std::vector<MosaicFrame>& frames,
                                                 const MosaicOptions& o) {
  if (frames.empty()) return Status::Error("mosaic: no frames");
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const MosaicFrame& f : frames) {
    const Eigen::Matrix3d H = imageToGround(f, o.ground_down);
    for (const Eigen::Vector2d& c : corners(f.image)) {
      const Eigen::Vector2d xy = applyHomography(H, c);
      const Eigen::Vector3d plane =
          f.ground_plane.value_or(Eigen::Vector3d(0.0, 0.0, o.ground_down));
      const double ground_below = plane.dot(Eigen::Vector3d(f.p_CinN.x(), f.p_CinN.y(), 1.0));
      if (f.p_CinN.z() >= ground_below || !xy.allFinite())
        return Status::Error("mosaic: a camera is not above the ground plane");
      x0 = std::min(x0, xy.x());
      y0 = std::min(y0, xy.y());
      x1 = std::max(x1, xy.x());
      y1 = std::max(y1, xy.y());
    }
  }
  MosaicGrid g;
  g.gsd = o.gsd;
  g.x_max = x1 + o.margin;
  g.y_min = y0 - o.margin;
  g.cols = static_cast<int>(std::ceil((y1 - y0 + 2 * o.margin) / o.gsd)) + 1;
  g.rows = static_cast<int>(std::ceil((x1 - x0 + 2 * o.margin) / o.gsd)) + 1;
  if (static_cast<double>(g.cols) * g.rows > o.max_megapixels * 1e6)
    return Status::Error("mosaic: " + std::to_string(g.cols) + "×" + std::to_string(g.rows) +
                         " pixels exceed max_megapixels (raise gsd)");
  return g;
}

Status MosaicBuilder::add(const MosaicFrame& frame) {
  if (frame.image.empty() || frame.image.type() != CV_8U)
    return Status::Error("mosaic: frame images must be 8-bit grey");
  FramePlacement p;
  p.prior = grid_.groundToPixel() * imageToGround(frame, o_.ground_down);
  Stored st;
  std::vector<cv::Point> poly;
  for (const Eigen::Vector2d& c : corners(frame.image)) {
    st.footprint.corners.push_back(applyHomography(p.prior, c));
    poly.emplace_back(cvRound(st.footprint.corners.back().x()),
                      cvRound(st.footprint.corners.back().y()));
  }
  st.footprint.centre = applyHomography(
      p.prior, Eigen::Vector2d(0.5 * (frame.image.cols - 1), 0.5 * (frame.image.rows - 1)));
  st.box = cv::boundingRect(poly);
  if (o_.register_frames) {
    if (Status s = vision::detectAdaptiveSift(frame.image, reg_.sift, &st.features); !s.ok())
      return s;
  }
  frames_.push_back(frame);
  stored_.push_back(std::move(st));
  placements_.push_back(p);
  // Smoothness of the correction along this UAV's track (mosaic_adjustment.h).
  const int k_new = static_cast<int>(frames_.size()) - 1;
  for (int j = k_new - 1; j >= 0; --j) {
    if (frames_[static_cast<std::size_t>(j)].agent != frame.agent) continue;
    const FramePrior& fp = stored_.back().footprint;
    links_.push_back({k_new, j, fp.centre, fp.centre, FrameLink::kSmooth});
    for (const Eigen::Vector2d& c : fp.corners)
      links_.push_back({k_new, j, c, c, FrameLink::kSmooth});
    break;
  }
  if (!o_.register_frames) return Status::Ok();

  // The earlier frames overlapping this one most, half of the slots for other UAVs (the
  // cooperative links), the rest for the same UAV (its own track, and revisits).
  const std::size_t k = frames_.size() - 1;
  std::vector<std::pair<double, std::size_t>> same, other;
  const cv::Rect& bk = stored_[k].box;
  for (std::size_t j = 0; j < k; ++j) {
    const cv::Rect& bj = stored_[j].box;
    const double overlap = static_cast<double>((bk & bj).area()) / std::min(bk.area(), bj.area());
    if (overlap < o_.min_overlap) continue;
    (frames_[j].agent == frame.agent ? same : other).emplace_back(overlap, j);
  }
  auto byOverlap = [](const auto& a, const auto& b) { return a.first > b.first; };
  std::sort(same.begin(), same.end(), byOverlap);
  std::sort(other.begin(), other.end(), byOverlap);
  const std::size_t slots = static_cast<std::size_t>(o_.max_neighbours);
  const std::size_t n_other = std::min(
      other.size(), std::max(slots - (slots + 1) / 2, slots - std::min(slots, same.size())));
  const std::size_t n_same = std::min(same.size(), slots - n_other);
  for (std::size_t i = 0; i < n_same; ++i) linkTo(k, same[i].second);
  for (std::size_t i = 0; i < n_other; ++i) linkTo(k, other[i].second);
  return Status::Ok();
}

void MosaicBuilder::linkTo(std::size_t k, std::size_t j) {
  const Eigen::Matrix3d& Gk = placements_[k].prior;
  const Eigen::Matrix3d& Gj = placements_[j].prior;
  const Eigen::Matrix3d prior = Gj.inverse() * Gk;  // image k → image j
  auto r = registerFeatures(stored_[k].features, stored_[j].features, reg_, prior);
  if (!r.ok()) return;
  double move = 0.0;
  for (const Eigen::Vector2d& c : corners(frames_[k].image))
    move = std::max(move, (applyHomography(r->estimate.H, c) - applyHomography(prior, c)).norm());
  if (move > o_.max_correction_px) return;
  // Keep at most max_links_per_pair inliers, spread along the match list.
  std::vector<std::size_t> inliers;
  for (std::size_t m = 0; m < r->estimate.inliers.size(); ++m)
    if (r->estimate.inliers[m]) inliers.push_back(m);
  const std::size_t step =
      std::max<std::size_t>(1, inliers.size() / static_cast<std::size_t>(o_.max_links_per_pair));
  int added = 0;
  for (std::size_t q = 0; q < inliers.size(); q += step) {
    links_.push_back({static_cast<int>(k), static_cast<int>(j),
                      applyHomography(Gk, r->src[inliers[q]]),
                      applyHomography(Gj, r->dst[inliers[q]]),
                      frames_[k].agent != frames_[j].agent ? FrameLink::kCross : FrameLink::kOwn});
    ++added;
  }
  placements_[k].registered_pairs += 1;
  placements_[k].links += added;
}

GainBias MosaicBuilder::photometricCorrection(const cv::Mat& image,
                                              const Eigen::Matrix3d& H) const {
  const cv::Rect box = warpedBox(image, H, 0.0, sum_.size());
  if (box.area() == 0) return {};
  const cv::Matx33d M = toMatx(translation(-box.x, -box.y) * H);
  cv::Mat warped, valid;
  cv::warpPerspective(image, warped, M, box.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::warpPerspective(cv::Mat(image.size(), CV_8U, cv::Scalar(255)), valid, M, box.size(),
                      cv::INTER_NEAREST, cv::BORDER_CONSTANT);
  cv::Mat mask = valid & (weight_(box) > 0.0f);
  cv::Mat current = sum_(box) / cv::max(weight_(box), 1e-6f);
  if (photo_.smoothing_px > 0.0) {
    // Smoothed, so that residual misregistration is not read as a loss of contrast; the
    // mask shrinks by the kernel so that unmapped (black) pixels do not bleed in.
    cv::GaussianBlur(warped, warped, cv::Size(0, 0), photo_.smoothing_px);
    cv::GaussianBlur(current, current, cv::Size(0, 0), photo_.smoothing_px);
    cv::erode(mask, mask, cv::Mat(), cv::Point(-1, -1),
              static_cast<int>(std::ceil(2.0 * photo_.smoothing_px)));
  }
  const auto g = estimateGainBias(warped, current, mask, photo_);
  return g.ok() ? *g : GainBias{};
}

Expected<std::vector<FramePlacement>> MosaicBuilder::finish() {
  std::vector<FramePrior> priors;
  for (const Stored& s : stored_) priors.push_back(s.footprint);
  std::vector<Eigen::Matrix3d> corrections(frames_.size(), Eigen::Matrix3d::Identity());
  if (o_.register_frames) {
    auto adjusted = adjustFrames(priors, links_, o_.adjustment);
    if (!adjusted.ok()) return adjusted.status();
    corrections = std::move(*adjusted);
  }
  sum_.setTo(0);
  weight_.setTo(0);
  for (std::size_t k = 0; k < frames_.size(); ++k) {
    FramePlacement& p = placements_[k];
    p.H = corrections[k] * p.prior;
    cv::Mat image;
    frames_[k].image.convertTo(image, CV_32F);
    if (photo_.enabled) {
      p.photometric = photometricCorrection(image, p.H);
      image = image * p.photometric.gain + p.photometric.bias;
    }
    blend(image, p.H);
  }
  return placements_;
}

void MosaicBuilder::blend(const cv::Mat& image, const Eigen::Matrix3d& H) {
  if (feather_.size() != image.size()) {
    // Distance to the image border, ramped to 1 over feather_px (and never 0 inside).
    cv::Mat inner(image.size(), CV_8U, cv::Scalar(255));
    inner.row(0).setTo(0);
    inner.row(inner.rows - 1).setTo(0);
    inner.col(0).setTo(0);
    inner.col(inner.cols - 1).setTo(0);
    cv::Mat dist;
    cv::distanceTransform(inner, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    feather_ = cv::min((dist + 1.0f) / static_cast<float>(o_.feather_px), 1.0f);
  }
  const cv::Rect box = warpedBox(image, H, 1.0, sum_.size());
  if (box.area() == 0) return;
  const cv::Matx33d M = toMatx(translation(-box.x, -box.y) * H);
  cv::Mat warped, w;
  cv::warpPerspective(image, warped, M, box.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::warpPerspective(feather_, w, M, box.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  sum_(box) += warped.mul(w);
  weight_(box) += w;
}

cv::Mat MosaicBuilder::image(int background) const {
  cv::Mat out;
  cv::Mat(sum_ / cv::max(weight_, 1e-6f)).convertTo(out, CV_8U);
  out.setTo(background, weight_ <= 0.0f);
  return out;
}

}  // namespace cvslam::mosaic
