#pragma once
// Keypoints and descriptors of one image (thesis §4.2.3–4.2.5), as every detector returns them.
//
// Descriptors are one row of bytes per keypoint (cv::Mat CV_8U):
//  - SIFT: 128 bytes, the gradient histogram quantised to 0..255 as OpenCV stores it (the
//    float descriptor is exactly these integers, so nothing is lost). The byte form makes the
//    L∞, L2 and angle distances of §4.2.6 integer loops the compiler vectorises.
//  - ORB: 32 bytes, 256 binary tests, compared by Hamming distance.
//  - SWIF: 64 bytes, orientation histograms of the wavelet details relative to the dominant
//    orientation (thesis §4.4.7, swif.h), unit-normalised and quantised like SIFT's, so the
//    same L2 / L∞ / angle criteria apply.

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace cvslam::vision {

enum class DescriptorType : uint8_t {
  kSift = 0,  ///< 128 bytes, histogram values 0..255
  kOrb = 1,   ///< 32 bytes, binary
  kSwif = 2,  ///< 64 bytes, histogram values 0..255 (swif.h)
};

/// Bytes per descriptor row.
inline int descriptorBytes(DescriptorType type) {
  switch (type) {
    case DescriptorType::kSift:
      return 128;
    case DescriptorType::kOrb:
      return 32;
    case DescriptorType::kSwif:
      return 64;  // kSwifDescriptorBytes (swif.h)
  }
  return 0;
}

struct Features {
  DescriptorType type = DescriptorType::kSift;
  std::vector<cv::KeyPoint> keypoints;  ///< pt [px], size = scale [px], angle [deg]
  cv::Mat descriptors;                  ///< keypoints.size() × descriptorBytes(type), CV_8U

  std::size_t size() const { return keypoints.size(); }
  const uint8_t* descriptor(std::size_t i) const {
    return descriptors.ptr<uint8_t>(static_cast<int>(i));
  }
};

}  // namespace cvslam::vision
