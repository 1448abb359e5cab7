// cvslam_build_vocabulary — builds the visual vocabulary of the feature index (docs/conventions.md
// thesis §6.6.3) from a folder of images: detect features with the front end's detector, then
// hierarchical k-means (vision/vocabulary.h). Every agent must load the same output file.

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "cvslam/vision/feature_detector.h"
#include "cvslam/vision/vocabulary.h"

namespace {

constexpr const char* kUsage = R"(usage: cvslam_build_vocabulary --images DIR [options]

Builds a visual vocabulary (hierarchical k-means over descriptors) from the images in DIR
(*.png, *.jpg, *.pgm, sorted by name) for the feature index shared by all agents.

options:
  --images DIR            folder of images (required)
  --output FILE           vocabulary file to write (default: vocabulary.cvoc)
  --detector NAME         adaptive_sift | sift | orb (default: adaptive_sift)
  --branching K           children per tree node (default: 32)
  --depth D               tree levels; up to K^D words (default: 2)
  --iterations N          Lloyd iterations per k-means (default: 12)
  --seed S                random seed (default: 20240229)
  --every N               use every N-th image (default: 1)
  --max-descriptors N     training descriptors kept, evenly subsampled (default: 60000)
  --help                  this text
)";

int fail(const std::string& message) {
  std::cerr << "cvslam_build_vocabulary: " << message << "\n";
  return 1;
}

bool parseInt(const std::string& text, long min, long max, long* out) {
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (end == text.c_str() || *end != '\0' || v < min || v > max) return false;
  *out = v;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  using namespace cvslam::vision;
  std::string images_dir;
  std::string output = "vocabulary.cvoc";
  std::string detector_name = "adaptive_sift";
  long every = 1;
  VocabularyOptions vo;
  vo.branching = 32;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      return 0;
    }
    if (i + 1 >= argc) return fail("option " + arg + " needs a value (see --help)");
    const std::string value = argv[++i];
    long v = 0;
    if (arg == "--images") {
      images_dir = value;
    } else if (arg == "--output") {
      output = value;
    } else if (arg == "--detector") {
      detector_name = value;
    } else if (arg == "--branching" && parseInt(value, 2, 256, &v)) {
      vo.branching = static_cast<int>(v);
    } else if (arg == "--depth" && parseInt(value, 1, 4, &v)) {
      vo.depth = static_cast<int>(v);
    } else if (arg == "--iterations" && parseInt(value, 1, 1000, &v)) {
      vo.iterations = static_cast<int>(v);
    } else if (arg == "--seed" && parseInt(value, 0, 4294967295L, &v)) {
      vo.seed = static_cast<uint32_t>(v);
    } else if (arg == "--every" && parseInt(value, 1, 1000000, &v)) {
      every = v;
    } else if (arg == "--max-descriptors" && parseInt(value, 2, 100000000, &v)) {
      vo.max_descriptors = static_cast<int>(v);
    } else {
      return fail("bad option or value: " + arg + " " + value + " (see --help)");
    }
  }
  if (images_dir.empty()) return fail("--images DIR is required (see --help)");
  DetectorOptions dopt;
  if (detector_name == "adaptive_sift") {
    dopt.type = DetectorType::kAdaptiveSift;
  } else if (detector_name == "sift") {
    dopt.type = DetectorType::kSift;
  } else if (detector_name == "orb") {
    dopt.type = DetectorType::kOrb;
  } else {
    return fail("--detector must be adaptive_sift, sift or orb (got '" + detector_name + "')");
  }
  std::error_code ec;
  if (!fs::is_directory(images_dir, ec)) return fail("not a folder: " + images_dir);
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(images_dir, ec)) {
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (e.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".pgm"))
      files.push_back(e.path());
  }
  if (ec) return fail("cannot list " + images_dir + ": " + ec.message());
  std::sort(files.begin(), files.end());
  if (files.empty()) return fail("no .png/.jpg/.pgm images in " + images_dir);

  cv::setNumThreads(1);  // reproducible, and the machine is shared
  auto detector = makeFeatureDetector(dopt);
  if (!detector.ok()) return fail(detector.status().message());
  cv::Mat all;
  int used = 0;
  for (std::size_t k = 0; k < files.size(); k += static_cast<std::size_t>(every)) {
    const cv::Mat img = cv::imread(files[k].string(), cv::IMREAD_GRAYSCALE);
    if (img.empty()) return fail("cannot read image " + files[k].string());
    Features f;
    if (auto s = (*detector)->detect(img, &f); !s.ok()) return fail(s.message());
    if (!f.descriptors.empty()) all.push_back(f.descriptors);
    ++used;
  }
  auto vocab = Vocabulary::train(all, (*detector)->descriptorType(), vo);
  if (!vocab.ok()) return fail(vocab.status().message());
  if (auto s = vocab->save(output); !s.ok()) return fail(s.message());
  std::cout << "vocabulary: " << vocab->wordCount() << " words (branching " << vo.branching
            << ", depth " << vo.depth << ", " << detector_name << ") from " << all.rows
            << " descriptors of " << used << " images -> " << output << "\n";
  return 0;
}
