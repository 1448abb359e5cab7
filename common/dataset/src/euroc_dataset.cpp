#include "cvslam/dataset/euroc_dataset.h"

#include <opencv2/imgcodecs.hpp>

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace cvslam {
namespace fs = std::filesystem;
namespace {

struct CsvRow {
  int line = 0;
  std::vector<std::string> fields;
};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

// Rows of a EuRoC CSV file (comment lines start with '#'), each with exactly `columns` fields.
Expected<std::vector<CsvRow>> readCsv(const std::string& path, std::size_t columns) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": missing or unreadable");
  std::vector<CsvRow> rows;
  std::string text;
  for (int line = 1; std::getline(in, text); ++line) {
    text = trim(text);
    if (text.empty() || text[0] == '#') continue;
    CsvRow row;
    row.line = line;
    std::size_t start = 0;
    while (true) {
      const auto comma = text.find(',', start);
      row.fields.push_back(trim(text.substr(start, comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (row.fields.size() != columns)
      return Status::Error(path + ":" + std::to_string(line) + ": expected " +
                           std::to_string(columns) + " comma-separated fields, got " +
                           std::to_string(row.fields.size()));
    rows.push_back(std::move(row));
  }
  return rows;
}

std::string where(const std::string& path, const CsvRow& row) {
  return path + ":" + std::to_string(row.line) + ": ";
}

Status parseTime(const std::string& path, const CsvRow& row, int64_t& t) {
  const std::string& f = row.fields[0];
  const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), t);
  if (ec != std::errc() || end != f.data() + f.size() || t < 0)
    return Status::Error(where(path, row) + "bad timestamp '" + f + "' (expected integer ns)");
  return Status::Ok();
}

Status parseNumber(const std::string& path, const CsvRow& row, std::size_t k, double& x) {
  const std::string& f = row.fields[k];
  char* end = nullptr;
  x = std::strtod(f.c_str(), &end);
  if (f.empty() || end != f.c_str() + f.size() || !std::isfinite(x))
    return Status::Error(where(path, row) + "field " + std::to_string(k + 1) + ": bad number '" +
                         f + "'");
  return Status::Ok();
}

// Timestamps must increase strictly (sorted, no duplicates).
Status checkIncreasing(const std::string& path, const CsvRow& row, int64_t previous, int64_t t,
                       bool first) {
  if (first || t > previous) return Status::Ok();
  return Status::Error(where(path, row) + "timestamp " + std::to_string(t) +
                       (t == previous
                            ? " duplicates the previous one"
                            : " is before the previous one (" + std::to_string(previous) + ")"));
}

// Reads the size from a PNG's IHDR chunk without decoding the image.
Expected<cv::Size> pngSize(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": image listed in data.csv is missing");
  unsigned char h[24] = {};
  in.read(reinterpret_cast<char*>(h), sizeof h);
  static constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (in.gcount() != 24 || !std::equal(kSignature, kSignature + 8, h) || h[12] != 'I' ||
      h[13] != 'H' || h[14] != 'D' || h[15] != 'R')
    return Status::Error(path + ": not a readable PNG");
  auto be32 = [&](int o) {
    return static_cast<int>((uint32_t{h[o]} << 24) | (uint32_t{h[o + 1]} << 16) |
                            (uint32_t{h[o + 2]} << 8) | uint32_t{h[o + 3]});
  };
  return cv::Size(be32(16), be32(20));
}

struct ImageList {
  std::vector<int64_t> t_ns;
  std::vector<std::string> paths;
};

Expected<ImageList> readImageList(const std::string& cam_dir) {
  const std::string csv = cam_dir + "/data.csv";
  if (!fs::is_directory(cam_dir)) return Status::Error(cam_dir + ": folder missing");
  if (!fs::is_directory(cam_dir + "/data")) return Status::Error(cam_dir + "/data: folder missing");
  auto rows = readCsv(csv, 2);
  if (!rows.ok()) return rows.status();
  ImageList list;
  for (const CsvRow& row : *rows) {
    int64_t t = 0;
    Status s = parseTime(csv, row, t);
    if (s.ok())
      s = checkIncreasing(csv, row, list.t_ns.empty() ? 0 : list.t_ns.back(), t, list.t_ns.empty());
    if (!s.ok()) return s;
    if (row.fields[1].empty()) return Status::Error(where(csv, row) + "empty file name");
    list.t_ns.push_back(t);
    list.paths.push_back(cam_dir + "/data/" + row.fields[1]);
  }
  if (list.t_ns.empty()) return Status::Error(csv + ": no images listed");
  return list;
}

Status checkSizes(const ImageList& list, const cv::Size& expected, const std::string& why) {
  for (const std::string& p : list.paths) {
    auto size = pngSize(p);
    if (!size.ok()) return size.status();
    if (*size != expected)
      return Status::Error(p + ": image is " + std::to_string(size->width) + "x" +
                           std::to_string(size->height) + ", expected " +
                           std::to_string(expected.width) + "x" + std::to_string(expected.height) +
                           " (" + why + ")");
  }
  return Status::Ok();
}

/// The estimator propagates the vehicle from the first stereo frame on with the IMU: a
/// recording whose IMU starts well after its first frame (a logger started late, a cut
/// file) cannot be used from that frame. A delay of a few samples is normal jitter between
/// drivers; kMaxImuStartDelayNs (20 samples at EuRoC's 200 Hz) separates the two.
constexpr int64_t kMaxImuStartDelayNs = 100'000'000;

Status checkImuCoversStart(const std::string& imu_csv, const std::vector<int64_t>& imu_t_ns,
                           int64_t first_frame_ns) {
  if (imu_t_ns.empty()) return Status::Error(imu_csv + ": no IMU samples");
  if (imu_t_ns.front() - first_frame_ns > kMaxImuStartDelayNs)
    return Status::Error(imu_csv + ": the IMU starts " +
                         std::to_string((imu_t_ns.front() - first_frame_ns) / 1'000'000) +
                         " ms after the first stereo frame (" + std::to_string(first_frame_ns) +
                         " ns): missing IMU at the start");
  return Status::Ok();
}

}  // namespace

Expected<EurocDataset> EurocDataset::open(const std::string& path) {
  EurocDataset d;
  d.mav0_ = fs::path(path).filename() == "mav0" ? path : path + "/mav0";
  if (!fs::is_directory(d.mav0_))
    return Status::Error(d.mav0_ + ": folder missing (not a EuRoC ASL dataset)");

  // Optional calibrations; a present but broken file is an error.
  const std::string c0 = d.mav0_ + "/cam0/sensor.yaml", c1 = d.mav0_ + "/cam1/sensor.yaml";
  const std::string i0 = d.mav0_ + "/imu0/sensor.yaml";
  if (fs::exists(c0)) {
    auto info = readEurocCameraYaml(c0);
    if (!info.ok()) return info.status();
    d.cam0_info_ = *info;
  }
  if (fs::exists(c1)) {
    auto info = readEurocCameraYaml(c1);
    if (!info.ok()) return info.status();
    d.cam1_info_ = *info;
  }
  if (fs::exists(i0)) {
    auto info = readEurocImuYaml(i0);
    if (!info.ok()) return info.status();
    d.imu_info_ = *info;
  }

  auto left = readImageList(d.mav0_ + "/cam0");
  if (!left.ok()) return left.status();
  auto right = readImageList(d.mav0_ + "/cam1");
  if (!right.ok()) return right.status();

  // Pair by exact timestamp (both lists strictly increasing). Unpaired entries are only
  // counted: in real recordings their image files may be absent (EuRoC V1_01's cam1 lists
  // frames it has no PNG for).
  ImageList left_paired, right_paired;
  std::size_t a = 0, b = 0;
  while (a < left->t_ns.size() && b < right->t_ns.size()) {
    if (left->t_ns[a] == right->t_ns[b]) {
      d.frames_.push_back({left->t_ns[a], left->paths[a], right->paths[b]});
      left_paired.paths.push_back(left->paths[a]);
      right_paired.paths.push_back(right->paths[b]);
      ++a;
      ++b;
    } else if (left->t_ns[a] < right->t_ns[b]) {
      ++a;
      ++d.unpaired_left_;
    } else {
      ++b;
      ++d.unpaired_right_;
    }
  }
  d.unpaired_left_ += static_cast<int>(left->t_ns.size() - a);
  d.unpaired_right_ += static_cast<int>(right->t_ns.size() - b);
  if (d.frames_.empty())
    return Status::Error(d.mav0_ + ": no cam0/cam1 frames with equal timestamps");

  // Headers of every paired image: present, PNG, expected size.
  std::string why = "resolution in cam0/sensor.yaml";
  if (d.cam0_info_) {
    d.image_size_ = cv::Size(d.cam0_info_->width, d.cam0_info_->height);
  } else {
    auto first = pngSize(left_paired.paths.front());
    if (!first.ok()) return first.status();
    d.image_size_ = *first;
    why = "size of the first cam0 image";
  }
  Status s = checkSizes(left_paired, d.image_size_, why);
  if (!s.ok()) return s;
  const cv::Size right_size =
      d.cam1_info_ ? cv::Size(d.cam1_info_->width, d.cam1_info_->height) : d.image_size_;
  s = checkSizes(right_paired, right_size, d.cam1_info_ ? "resolution in cam1/sensor.yaml" : why);
  if (!s.ok()) return s;

  const std::string imu_csv = d.mav0_ + "/imu0/data.csv";
  auto imu_rows = readCsv(imu_csv, 7);
  if (!imu_rows.ok()) return imu_rows.status();
  for (const CsvRow& row : *imu_rows) {
    int64_t t = 0;
    s = parseTime(imu_csv, row, t);
    if (s.ok())
      s = checkIncreasing(imu_csv, row, d.imu_t_ns_.empty() ? 0 : d.imu_t_ns_.back(), t,
                          d.imu_t_ns_.empty());
    double v[6];
    for (std::size_t k = 0; k < 6 && s.ok(); ++k) s = parseNumber(imu_csv, row, k + 1, v[k]);
    if (!s.ok()) return s;
    ImuSample sample;
    sample.t_us = (t + 500) / 1000;  // nearest microsecond
    sample.gyro_B = {v[0], v[1], v[2]};
    sample.accel_B = {v[3], v[4], v[5]};
    d.imu_.push_back(sample);
    d.imu_t_ns_.push_back(t);
  }
  s = checkImuCoversStart(imu_csv, d.imu_t_ns_, d.frames_.front().t_ns);
  if (!s.ok()) return s;

  const std::string gt_csv = d.mav0_ + "/state_groundtruth_estimate0/data.csv";
  if (fs::exists(gt_csv)) {
    auto gt_rows = readCsv(gt_csv, 17);
    if (!gt_rows.ok()) return gt_rows.status();
    for (const CsvRow& row : *gt_rows) {
      EurocGroundTruth g;
      s = parseTime(gt_csv, row, g.t_ns);
      if (s.ok())
        s = checkIncreasing(gt_csv, row, d.ground_truth_.empty() ? 0 : d.ground_truth_.back().t_ns,
                            g.t_ns, d.ground_truth_.empty());
      double v[16];
      for (std::size_t k = 0; k < 16 && s.ok(); ++k) s = parseNumber(gt_csv, row, k + 1, v[k]);
      if (!s.ok()) return s;
      g.p_SinR = {v[0], v[1], v[2]};
      g.q_StoR = Eigen::Quaterniond(v[3], v[4], v[5], v[6]);
      g.v_SinR = {v[7], v[8], v[9]};
      g.gyro_bias = {v[10], v[11], v[12]};
      g.accel_bias = {v[13], v[14], v[15]};
      d.ground_truth_.push_back(g);
    }
  }
  return d;
}

Expected<EurocStereoFrame> EurocDataset::loadFrame(std::size_t i) const {
  if (i >= frames_.size())
    return Status::Error(mav0_ + ": frame " + std::to_string(i) + " out of range (" +
                         std::to_string(frames_.size()) + " frames)");
  EurocStereoFrame f;
  f.t_ns = frames_[i].t_ns;
  for (auto [path, image] : {std::pair{&frames_[i].left, &f.left}, {&frames_[i].right, &f.right}}) {
    *image = cv::imread(*path, cv::IMREAD_GRAYSCALE);
    if (image->empty()) return Status::Error(*path + ": cannot decode PNG");
    if (image->size() != image_size_ && (path == &frames_[i].left || !cam1_info_))
      return Status::Error(*path + ": decoded image has the wrong size");
  }
  return f;
}

}  // namespace cvslam
