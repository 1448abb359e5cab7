// cvslam_build_vocabulary — builds the visual vocabulary of the feature index (docs/conventions.md
// thesis §6.6.3) from a folder of images: detect features with the front end's detector, then
// hierarchical k-means (vision/vocabulary.h). Every agent must load the same output file.

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "cvslam/io/cli.h"
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
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  using namespace cvslam::vision;
  std::string images_dir;
  std::string output = "vocabulary.cvoc";
  std::string detector_name = "adaptive_sift";
  int every = 1;
  VocabularyOptions vo;
  vo.branching = 32;
  CLI::App app("builds a visual vocabulary", "cvslam_build_vocabulary");
  app.add_option("--images", images_dir)->required();
  app.add_option("--output", output);
  const std::map<std::string, DetectorType> detectors = {
      {"adaptive_sift", DetectorType::kAdaptiveSift},
      {"sift", DetectorType::kSift},
      {"orb", DetectorType::kOrb}};
  app.add_option("--detector", detector_name)->check(CLI::IsMember(detectors));
  app.add_option("--branching", vo.branching)->check(CLI::Range(2, 256));
  app.add_option("--depth", vo.depth)->check(CLI::Range(1, 4));
  app.add_option("--iterations", vo.iterations)->check(CLI::Range(1, 1000));
  app.add_option("--seed", vo.seed);  // uint32_t: CLI11 rejects negatives and overflow
  app.add_option("--every", every)->check(CLI::Range(1, 1000000));
  app.add_option("--max-descriptors", vo.max_descriptors)->check(CLI::Range(2, 100000000));
  if (auto exit_code = cvslam::cli::parse(app, argc, argv, kUsage)) return *exit_code;
  DetectorOptions dopt;
  dopt.type = detectors.at(detector_name);
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
