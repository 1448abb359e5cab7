#pragma once
// Visual vocabulary for the feature index (docs/conventions.md; thesis §6.6.3): a small
// hierarchical k-means tree over descriptors. A feature's index is the id of the leaf
// ("visual word") its descriptor falls into, so the same physical feature gets the same
// 32-bit index on every UAV that loads the same vocabulary file.
//
// Determinism: training uses the project's seeded Rng (core/random.h, identical on every
// platform); centres are rounded to bytes after every
// Lloyd iteration so that all assignments are exact integer comparisons (ties → lowest
// index). Word lookup is integer-only: identical inputs give identical word ids anywhere.
//
// File (little-endian binary): "CVSLVOC\0", uint32 version (1), uint32 descriptor type,
// uint32 descriptor bytes, uint32 branching, uint32 depth, uint32 node count, then per node
// int32 first child, int32 child count, uint32 word id (leaves; else 0xFFFFFFFF) and the
// centre's bytes. Node 0 is the root (no centre meaning).

#include <cstdint>
#include <string>
#include <vector>

#include "cvslam/core/random.h"
#include "cvslam/core/status.h"
#include "cvslam/vision/features.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::vision {

struct VocabularyOptions {
  int branching = 16;           ///< children per node (k of each k-means)
  int depth = 2;                ///< levels below the root: up to branching^depth words
  int iterations = 12;          ///< Lloyd iterations per k-means
  uint32_t seed = 20240229;     ///< random seed (k-means++ initialisation)
  int max_descriptors = 60000;  ///< training descriptors kept (evenly subsampled)

  Status load(const ConfigNode& node);
};

class Vocabulary {
 public:
  static constexpr uint32_t kVersion = 1;
  static constexpr uint32_t kNoWord = 0xFFFFFFFFu;

  /// Trains on descriptor rows (CV_8U, descriptorBytes(type) columns).
  static Expected<Vocabulary> train(const cv::Mat& descriptors, DescriptorType type,
                                    const VocabularyOptions& options);
  static Expected<Vocabulary> load(const std::string& path);
  Status save(const std::string& path) const;

  /// Word id of one descriptor (descriptorBytes(type()) bytes).
  uint32_t word(const uint8_t* descriptor) const;
  /// Word ids of every feature (empty if the descriptor type differs).
  std::vector<uint32_t> words(const Features& features) const;

  DescriptorType type() const { return type_; }
  int wordCount() const { return word_count_; }
  int branching() const { return branching_; }
  int depth() const { return depth_; }

 private:
  struct Node {
    int32_t first_child = -1;
    int32_t child_count = 0;
    uint32_t word = kNoWord;
  };
  Vocabulary() = default;
  int distance(const uint8_t* a, const uint8_t* b) const;
  void build(int node, const cv::Mat& data, const std::vector<int>& rows, int level,
             const VocabularyOptions& o, Rng* rng);

  DescriptorType type_ = DescriptorType::kSift;
  int bytes_ = 128;
  int branching_ = 0;
  int depth_ = 0;
  int word_count_ = 0;
  std::vector<Node> nodes_;
  std::vector<uint8_t> centres_;  ///< nodes_.size() × bytes_
};

}  // namespace cvslam::vision
