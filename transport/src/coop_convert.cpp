#include "cvslam/lcm/coop_convert.h"

#include "covariance_triangle.h"
#include "cvslam/lcm/message_finalize.h"

namespace cvslam::transport {

namespace {
cvslam::header_t toHeader(const coop::CoopHeader& h) {
  cvslam::header_t m{};
  m.utime = h.t_us;
  m.seq = h.seq;
  m.agent_id = h.agent_id;
  return m;
}

coop::CoopHeader fromHeader(const cvslam::header_t& m) {
  return {m.agent_id, m.seq, m.utime};
}

/// A cross-covariance block on the wire: 9 doubles, row-major (shared_landmarks2_t.lcm).
using RowMajor3 = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>;
using ConstRowMajor3 = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>;

std::vector<int32_t> toWire(const std::vector<uint32_t>& indices) {
  std::vector<int32_t> out;
  out.reserve(indices.size());
  for (uint32_t i : indices) out.push_back(static_cast<int32_t>(i));
  return out;
}

std::vector<uint32_t> fromWire(const std::vector<int32_t>& indices) {
  std::vector<uint32_t> out;
  out.reserve(indices.size());
  for (int32_t i : indices) out.push_back(static_cast<uint32_t>(i));
  return out;
}
}  // namespace

Expected<cvslam::agent_summary_t> toMessage(const coop::CoopSummary& s) {
  cvslam::agent_summary_t m{};
  m.header = toHeader(s.header);
  m.mode = s.mode;
  m.boot_id = s.boot_id;
  for (int k = 0; k < 3; ++k) {
    m.ellipsoid_mean[k] = s.mean(k);
    m.ellipsoid_std[k] = s.std(k);
  }
  m.num_features = s.num_features;
  m.vehicle_cov_trace = s.vehicle_cov_trace;
  m.own_frame = s.own_frame;
  return finalized(std::move(m));
}

coop::CoopSummary fromMessage(const cvslam::agent_summary_t& m) {
  coop::CoopSummary s;
  s.header = fromHeader(m.header);
  s.mode = m.mode;
  s.boot_id = m.boot_id;
  s.mean = Eigen::Vector3d(m.ellipsoid_mean[0], m.ellipsoid_mean[1], m.ellipsoid_mean[2]);
  s.std = Eigen::Vector3d(m.ellipsoid_std[0], m.ellipsoid_std[1], m.ellipsoid_std[2]);
  s.num_features = m.num_features;
  s.vehicle_cov_trace = m.vehicle_cov_trace;
  s.own_frame = m.own_frame;
  return s;
}

Expected<cvslam::feature_index_t> toMessage(const coop::FeatureIndexList& l) {
  cvslam::feature_index_t m{};
  m.header = toHeader(l.header);
  m.true_ids = l.true_ids;
  m.index = toWire(l.indices);
  return finalized(std::move(m));
}

coop::FeatureIndexList fromMessage(const cvslam::feature_index_t& m) {
  coop::FeatureIndexList l;
  l.header = fromHeader(m.header);
  l.true_ids = m.true_ids;
  l.indices = fromWire(m.index);
  return l;
}

Expected<cvslam::shared_request_t> toMessage(const coop::SharedRequest& r) {
  cvslam::shared_request_t m{};
  m.header = toHeader(r.header);
  m.index = toWire(r.indices);
  return finalized(std::move(m));
}

coop::SharedRequest fromMessage(const cvslam::shared_request_t& m, int to_agent) {
  coop::SharedRequest r;
  r.header = fromHeader(m.header);
  r.to_agent = to_agent;
  r.indices = fromWire(m.index);
  return r;
}

Expected<cvslam::shared_landmarks2_t> toMessage(const coop::SharedLandmarks& s) {
  cvslam::shared_landmarks2_t m{};
  m.header = toHeader(s.header);
  m.vehicle_cov_trace = s.vehicle_cov_trace;
  m.informed_by.assign(s.informed_by.begin(), s.informed_by.end());
  // One descriptor length per message: when the landmarks' lengths differ, none is sent (the
  // receiver then confirms by the Mahalanobis gate alone).
  bool same_length = true;
  for (const coop::SharedLandmark& l : s.landmarks)
    same_length &= l.descriptor.size() == s.landmarks.front().descriptor.size();
  for (const coop::SharedLandmark& l : s.landmarks) {
    m.index.push_back(static_cast<int32_t>(l.index));
    m.position.push_back({l.p_LinN.x(), l.p_LinN.y(), l.p_LinN.z()});
    m.covariance.push_back(upperTriangle(l.covariance));
    m.descriptors.push_back(same_length ? l.descriptor : std::vector<uint8_t>{});
  }
  const auto n = static_cast<Eigen::Index>(s.landmarks.size());
  if (n >= 2 && s.joint_covariance.rows() == 3 * n && s.joint_covariance.cols() == 3 * n) {
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index j = i + 1; j < n; ++j) {
        std::vector<double> block(9);
        RowMajor3(block.data()) = s.joint_covariance.block<3, 3>(3 * i, 3 * j);
        m.cross_covariance.push_back(std::move(block));
      }
  }
  return finalized(std::move(m));
}

coop::SharedLandmarks fromMessage(const cvslam::shared_landmarks2_t& m, int to_agent) {
  coop::SharedLandmarks s;
  s.header = fromHeader(m.header);
  s.to_agent = to_agent;
  s.vehicle_cov_trace = m.vehicle_cov_trace;
  s.informed_by.assign(m.informed_by.begin(), m.informed_by.end());
  // Sizes are trusted here: messages reach this point only through decodeMessage().
  s.landmarks.resize(m.index.size());
  for (std::size_t i = 0; i < m.index.size(); ++i) {
    coop::SharedLandmark& l = s.landmarks[i];
    l.index = static_cast<uint32_t>(m.index[i]);
    l.p_LinN = Eigen::Vector3d(m.position[i][0], m.position[i][1], m.position[i][2]);
    l.covariance = fromUpperTriangle(m.covariance[i]);
    if (i < m.descriptors.size()) l.descriptor = m.descriptors[i];
  }
  const auto n = static_cast<Eigen::Index>(s.landmarks.size());
  if (n >= 2 && m.cross_covariance.size() == static_cast<std::size_t>(n * (n - 1) / 2)) {
    s.joint_covariance.resize(3 * n, 3 * n);
    std::size_t row = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      s.joint_covariance.block<3, 3>(3 * i, 3 * i) =
          s.landmarks[static_cast<std::size_t>(i)].covariance;
      for (Eigen::Index j = i + 1; j < n; ++j, ++row) {
        const Eigen::Matrix3d block = ConstRowMajor3(m.cross_covariance[row].data());
        s.joint_covariance.block<3, 3>(3 * i, 3 * j) = block;
        s.joint_covariance.block<3, 3>(3 * j, 3 * i) = block.transpose();
      }
    }
  }
  return s;
}

}  // namespace cvslam::transport
