#pragma once
// Image pairs with a known homography for detector evaluation (SWIF, thesis §4.4.5–4.4.7; the
// thesis used Mikolajczyk's Oxford set, we use a rendered ground image): a nadir rendering of the
// textured aerial world, a reference crop of it, and the crop seen after a rotation, a scale
// change, an out-of-plane viewpoint change, blur or an illumination change.
// The transformed view is warped from the whole rendering, so no border is invented where the
// rendering has texture.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "cvslam/core/status.h"

namespace cvslam::render {

struct ViewChange {
  std::string family;                  ///< rotation | scale | viewpoint | blur | illumination
  double amount = 0;                   ///< degrees, scale factor, degrees, σ [px], or gain
  cv::Matx33d H = cv::Matx33d::eye();  ///< reference pixel → transformed pixel
  double blur_sigma = 0.0;             ///< Gaussian blur of the transformed view [px]
  double gain = 1.0;                   ///< illumination: I' = 255 · gain · (I/255)^gamma
  double gamma = 1.0;
};

struct ViewPair {
  ViewChange change;
  cv::Mat reference;    ///< CV_8UC1
  cv::Mat transformed;  ///< CV_8UC1, same size
};

/// side × side nadir rendering of the aerial world (textured ground, seeded) 10 m up.
Expected<cv::Mat> renderGroundImage(int side, uint64_t seed);

/// Rotation by `degrees` about the centre of a `size` image.
ViewChange rotationChange(double degrees, cv::Size size);
/// Zoom by `factor` about the centre.
ViewChange scaleChange(double factor, cv::Size size);
/// A camera (focal `focal_px`) turned by `degrees` about the x axis through the point of the
/// ground plane it looks at: the plane homography K R (I − C nᵀ/d) K⁻¹.
ViewChange viewpointChange(double degrees, cv::Size size, double focal_px);
ViewChange blurChange(double sigma);
ViewChange illuminationChange(double gain, double gamma);

/// The `size` centre crop of `ground` and its transformed view.
ViewPair makeViewPair(const cv::Mat& ground, cv::Size size, const ViewChange& change);

}  // namespace cvslam::render
