#include "cvslam/vision/vocabulary.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <limits>

#include "cvslam/io/config_node.h"
#include "cvslam/vision/descriptor_distance.h"

namespace cvslam::vision {

Status VocabularyOptions::load(const ConfigNode& node) {
  node.get("branching", branching);
  node.get("depth", depth);
  node.get("iterations", iterations);
  node.get("seed", seed);
  node.get("max_descriptors", max_descriptors);
  node.check(branching >= 2 && branching <= 256, "branching", "must be in [2, 256]");
  node.check(depth >= 1 && depth <= 4, "depth", "must be in [1, 4]");
  node.check(iterations >= 1, "iterations", "must be >= 1");
  node.check(max_descriptors >= branching, "max_descriptors", "must be >= branching");
  return node.status();
}

namespace {

constexpr char kMagic[8] = {'C', 'V', 'S', 'L', 'V', 'O', 'C', '\0'};

void putU32(std::ostream& os, uint32_t v) {
  const unsigned char b[4] = {static_cast<unsigned char>(v), static_cast<unsigned char>(v >> 8),
                              static_cast<unsigned char>(v >> 16),
                              static_cast<unsigned char>(v >> 24)};
  os.write(reinterpret_cast<const char*>(b), 4);
}

bool getU32(std::istream& is, uint32_t* v) {
  unsigned char b[4];
  if (!is.read(reinterpret_cast<char*>(b), 4)) return false;
  *v = static_cast<uint32_t>(b[0]) | (static_cast<uint32_t>(b[1]) << 8) |
       (static_cast<uint32_t>(b[2]) << 16) | (static_cast<uint32_t>(b[3]) << 24);
  return true;
}

}  // namespace

int Vocabulary::distance(const uint8_t* a, const uint8_t* b) const {
  return type_ == DescriptorType::kOrb ? distanceHamming(a, b, bytes_)
                                       : distanceL2Squared(a, b, bytes_);
}

void Vocabulary::build(int node, const cv::Mat& data, const std::vector<int>& rows, int level,
                       const VocabularyOptions& o, Rng* rng) {
  const int k = o.branching;
  const std::size_t un = static_cast<std::size_t>(node);
  if (level >= o.depth || static_cast<int>(rows.size()) <= k) {
    nodes_[un].word = static_cast<uint32_t>(word_count_++);
    return;
  }
  const std::size_t n = rows.size();
  const std::size_t B = static_cast<std::size_t>(bytes_);
  auto row = [&](std::size_t i) { return data.ptr<uint8_t>(rows[i]); };
  // k-means++ seeding.
  std::vector<uint8_t> centres(static_cast<std::size_t>(k) * B);
  std::vector<double> d2(n, std::numeric_limits<double>::max());
  std::size_t pick = static_cast<std::size_t>(rng->uniform() * static_cast<double>(n));
  for (int c = 0; c < k; ++c) {
    std::memcpy(&centres[static_cast<std::size_t>(c) * B], row(pick), B);
    double total = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double d = distance(row(i), &centres[static_cast<std::size_t>(c) * B]);
      d2[i] = std::min(d2[i], d * (type_ == DescriptorType::kOrb ? d : 1.0));
      total += d2[i];
    }
    const double target = rng->uniform() * total;
    double acc = 0;
    pick = n - 1;
    for (std::size_t i = 0; i < n; ++i) {
      acc += d2[i];
      if (acc > target) {
        pick = i;
        break;
      }
    }
  }
  // Lloyd iterations; centres rounded to bytes (mean for SIFT, bit majority for ORB).
  std::vector<int> assign(n, 0);
  for (int it = 0; it < o.iterations; ++it) {
    bool changed = false;
    for (std::size_t i = 0; i < n; ++i) {
      int best = 0;
      int best_d = std::numeric_limits<int>::max();
      for (int c = 0; c < k; ++c) {
        const int d = distance(row(i), &centres[static_cast<std::size_t>(c) * B]);
        if (d < best_d) {
          best_d = d;
          best = c;
        }
      }
      changed = changed || assign[i] != best;
      assign[i] = best;
    }
    if (it > 0 && !changed) break;
    const int bits = type_ == DescriptorType::kOrb ? 8 : 1;
    std::vector<double> sum(static_cast<std::size_t>(k) * B * static_cast<std::size_t>(bits), 0.0);
    std::vector<int> count(static_cast<std::size_t>(k), 0);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t c = static_cast<std::size_t>(assign[i]);
      ++count[c];
      const uint8_t* r = row(i);
      for (std::size_t b = 0; b < B; ++b) {
        if (bits == 1) {
          sum[c * B + b] += r[b];
        } else {
          for (int t = 0; t < 8; ++t)
            sum[(c * B + b) * 8 + static_cast<std::size_t>(t)] += (r[b] >> t) & 1;
        }
      }
    }
    for (std::size_t c = 0; c < static_cast<std::size_t>(k); ++c) {
      if (count[c] == 0) continue;  // empty cluster keeps its centre
      for (std::size_t b = 0; b < B; ++b) {
        if (bits == 1) {
          centres[c * B + b] = static_cast<uint8_t>(std::lround(sum[c * B + b] / count[c]));
        } else {
          int byte = 0;
          for (int t = 0; t < 8; ++t)
            if (2 * sum[(c * B + b) * 8 + static_cast<std::size_t>(t)] > count[c]) byte |= 1 << t;
          centres[c * B + b] = static_cast<uint8_t>(byte);
        }
      }
    }
  }
  // Children are contiguous; recurse depth-first (word ids in that order).
  const int first = static_cast<int>(nodes_.size());
  nodes_[un].first_child = first;
  nodes_[un].child_count = k;
  nodes_.resize(nodes_.size() + static_cast<std::size_t>(k));
  centres_.insert(centres_.end(), centres.begin(), centres.end());
  for (int c = 0; c < k; ++c) {
    std::vector<int> sub;
    for (std::size_t i = 0; i < n; ++i)
      if (assign[i] == c) sub.push_back(rows[i]);
    build(first + c, data, sub, level + 1, o, rng);
  }
}

Expected<Vocabulary> Vocabulary::train(const cv::Mat& descriptors, DescriptorType type,
                                       const VocabularyOptions& o) {
  const int bytes = descriptorBytes(type);
  if (descriptors.type() != CV_8U || descriptors.cols != bytes)
    return Status::Error("vocabulary: descriptors must be CV_8U rows of " + std::to_string(bytes) +
                         " bytes");
  if (descriptors.rows < o.branching)
    return Status::Error("vocabulary: need at least " + std::to_string(o.branching) +
                         " descriptors, got " + std::to_string(descriptors.rows));
  Vocabulary v;
  v.type_ = type;
  v.bytes_ = bytes;
  v.branching_ = o.branching;
  v.depth_ = o.depth;
  v.nodes_.resize(1);
  v.centres_.assign(static_cast<std::size_t>(bytes), 0);
  std::vector<int> rows;
  const int n = descriptors.rows;
  const int keep = std::min(n, o.max_descriptors);
  for (int i = 0; i < keep; ++i)
    rows.push_back(static_cast<int>(static_cast<int64_t>(i) * n / keep));
  Rng rng(o.seed);
  v.build(0, descriptors, rows, 0, o, &rng);
  return v;
}

uint32_t Vocabulary::word(const uint8_t* descriptor) const {
  std::size_t node = 0;
  while (nodes_[node].word == kNoWord) {
    const Node& nd = nodes_[node];
    int best = nd.first_child;
    int best_d = std::numeric_limits<int>::max();
    for (int c = nd.first_child; c < nd.first_child + nd.child_count; ++c) {
      const int d = distance(
          descriptor, &centres_[static_cast<std::size_t>(c) * static_cast<std::size_t>(bytes_)]);
      if (d < best_d) {
        best_d = d;
        best = c;
      }
    }
    node = static_cast<std::size_t>(best);
  }
  return nodes_[node].word;
}

std::vector<uint32_t> Vocabulary::words(const Features& f) const {
  std::vector<uint32_t> out;
  if (f.type != type_) return out;
  out.reserve(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) out.push_back(word(f.descriptor(i)));
  return out;
}

Status Vocabulary::save(const std::string& path) const {
  std::ofstream os(path, std::ios::binary);
  if (!os) return Status::Error("vocabulary: cannot write " + path);
  os.write(kMagic, 8);
  putU32(os, kVersion);
  putU32(os, static_cast<uint32_t>(type_));
  putU32(os, static_cast<uint32_t>(bytes_));
  putU32(os, static_cast<uint32_t>(branching_));
  putU32(os, static_cast<uint32_t>(depth_));
  putU32(os, static_cast<uint32_t>(nodes_.size()));
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    putU32(os, static_cast<uint32_t>(nodes_[i].first_child));
    putU32(os, static_cast<uint32_t>(nodes_[i].child_count));
    putU32(os, nodes_[i].word);
    os.write(reinterpret_cast<const char*>(&centres_[i * static_cast<std::size_t>(bytes_)]),
             bytes_);
  }
  if (!os) return Status::Error("vocabulary: write error on " + path);
  return Status::Ok();
}

Expected<Vocabulary> Vocabulary::load(const std::string& path) {
  std::ifstream is(path, std::ios::binary);
  if (!is) return Status::Error("vocabulary: cannot open " + path);
  char magic[8];
  if (!is.read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0)
    return Status::Error("vocabulary: " + path + " is not a cvslam vocabulary file");
  uint32_t version = 0, type = 0, bytes = 0, branching = 0, depth = 0, count = 0;
  if (!getU32(is, &version) || !getU32(is, &type) || !getU32(is, &bytes) ||
      !getU32(is, &branching) || !getU32(is, &depth) || !getU32(is, &count))
    return Status::Error("vocabulary: " + path + ": truncated header");
  if (version != kVersion)
    return Status::Error("vocabulary: " + path + ": version " + std::to_string(version) +
                         " not supported (expected " + std::to_string(kVersion) + ")");
  if (type > 1 ||
      bytes != static_cast<uint32_t>(descriptorBytes(static_cast<DescriptorType>(type))))
    return Status::Error("vocabulary: " + path + ": bad descriptor type/size");
  if (count == 0 || count > 10000000)
    return Status::Error("vocabulary: " + path + ": bad node count");
  Vocabulary v;
  v.type_ = static_cast<DescriptorType>(type);
  v.bytes_ = static_cast<int>(bytes);
  v.branching_ = static_cast<int>(branching);
  v.depth_ = static_cast<int>(depth);
  v.nodes_.resize(count);
  v.centres_.resize(static_cast<std::size_t>(count) * bytes);
  for (std::size_t i = 0; i < count; ++i) {
    uint32_t first = 0, n = 0, word = 0;
    if (!getU32(is, &first) || !getU32(is, &n) || !getU32(is, &word) ||
        !is.read(reinterpret_cast<char*>(&v.centres_[i * bytes]), bytes))
      return Status::Error("vocabulary: " + path + ": truncated at node " + std::to_string(i));
    Node& nd = v.nodes_[i];
    nd.first_child = static_cast<int32_t>(first);
    nd.child_count = static_cast<int32_t>(n);
    nd.word = word;
    const bool leaf = word != kNoWord;
    if (leaf) {
      v.word_count_ = std::max(v.word_count_, static_cast<int>(word) + 1);
    } else if (nd.first_child <= static_cast<int32_t>(i) || nd.child_count <= 0 ||
               static_cast<std::size_t>(nd.first_child) + static_cast<std::size_t>(nd.child_count) >
                   count) {
      return Status::Error("vocabulary: " + path + ": corrupt tree at node " + std::to_string(i));
    }
  }
  return v;
}

}  // namespace cvslam::vision
