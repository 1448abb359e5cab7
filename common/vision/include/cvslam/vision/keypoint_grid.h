#pragma once
// Spatially uniform keypoint selection: a grid over the image, cells served round-robin by
// descending response, until `max_keypoints` are kept. Spreads features over the image (better
// conditioned geometry for the filter) and stops a single repetitive object — a checkerboard,
// a row of identical windows — from taking most of the budget, which is where repeated-pattern
// mismatches come from.

#include <opencv2/core.hpp>
#include <vector>

namespace cvslam::vision {

/// Keeps at most `max_keypoints` of `keypoints`, round-robin over a cols × rows grid of
/// `image_size`, strongest first within each cell. Deterministic (ties by position).
std::vector<cv::KeyPoint> retainUniform(const std::vector<cv::KeyPoint>& keypoints,
                                        cv::Size image_size, int max_keypoints, int cols, int rows);

}  // namespace cvslam::vision
