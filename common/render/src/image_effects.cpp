#include "cvslam/render/image_effects.h"

#include <opencv2/imgproc.hpp>

#include "cvslam/io/config_node.h"
#include "cvslam/core/random.h"

namespace cvslam::render {

Status ImageEffectsOptions::load(const ConfigNode& node) {
  node.get("exposure", exposure);
  node.get("blur_sigma", blur_sigma);
  node.get("noise_sigma", noise_sigma);
  node.get("noise_seed", noise_seed);
  node.check(exposure > 0, "exposure", "must be > 0");
  node.check(blur_sigma >= 0, "blur_sigma", "must be >= 0");
  node.check(noise_sigma >= 0, "noise_sigma", "must be >= 0");
  return node.status();
}

void applyImageEffects(const ImageEffectsOptions& o, uint64_t stream, cv::Mat& image) {
  if (o.blur_sigma > 0) cv::GaussianBlur(image, image, cv::Size(0, 0), o.blur_sigma);
  if (o.noise_sigma > 0) {
    // A local cv::RNG (never cv::theRNG(), which is global state shared by all renderers).
    cv::RNG rng(mixBits(o.noise_seed ^ mixBits(stream)));
    cv::Mat1f noise(image.size());
    rng.fill(noise, cv::RNG::NORMAL, 0.0, o.noise_sigma);
    cv::Mat1f sum;
    image.convertTo(sum, CV_32F);
    sum += noise;
    sum.convertTo(image, CV_8U);  // rounds and saturates
  }
}

}  // namespace cvslam::render
