#include "cvslam/slam/dynamic_initializer.h"

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "cvslam/geometry/euler.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/ins/ins_propagator.h"
#include "cvslam/io/config_node.h"

namespace cvslam {

Status DynamicInitializerOptions::load(const ConfigNode& node) {
  node.get("window_s", window_s);
  node.get("min_tracks", min_tracks);
  node.get("ransac_iterations", ransac_iterations);
  node.get("reprojection_error_px", reprojection_error_px);
  node.get("max_depth", max_depth);
  node.get("match_radius_px", match_radius_px);
  node.get("max_gravity_error", max_gravity_error);
  node.get("tilt_sigma_min", tilt_sigma_min);
  node.get("velocity_sigma_min", velocity_sigma_min);
  node.get("gyro_bias_sigma_min", gyro_bias_sigma_min);
  node.get("max_imu_hold_s", max_imu_hold_s);
  if (node.has("matching")) {
    if (Status s = matching.load(node.child("matching")); !s.ok()) return s;
  }
  node.check(window_s > 0.0, "window_s", "must be > 0");
  node.check(min_tracks >= 4, "min_tracks", "must be >= 4 (a PnP fit needs 4 points)");
  node.check(ransac_iterations >= 1, "ransac_iterations", "must be >= 1");
  node.check(reprojection_error_px > 0.0, "reprojection_error_px", "must be > 0");
  node.check(max_depth > 0.0, "max_depth", "must be > 0");
  node.check(match_radius_px > 0.0, "match_radius_px", "must be > 0");
  node.check(max_gravity_error > 0.0, "max_gravity_error", "must be > 0");
  node.check(tilt_sigma_min > 0.0, "tilt_sigma_min", "must be > 0");
  node.check(velocity_sigma_min > 0.0, "velocity_sigma_min", "must be > 0");
  node.check(gyro_bias_sigma_min > 0.0, "gyro_bias_sigma_min", "must be > 0");
  node.check(max_imu_hold_s >= 0.0, "max_imu_hold_s", "must be >= 0");
  return node.status();
}

DynamicInitializer::DynamicInitializer(const DynamicInitializerOptions& options,
                                       const StereoCamera& camera, double gravity)
    : o_(options), camera_(camera), gravity_(gravity) {}

void DynamicInitializer::addImu(const ImuSample& sample) {
  imu_.push_back(sample);
}

std::vector<std::pair<int, int>> DynamicInitializer::track(const Frame& previous,
                                                           const Frame& current) const {
  std::vector<std::pair<int, int>> pairs;
  const auto& a = previous.observations;
  const auto& b = current.observations;
  const std::size_t bytes = a.empty() ? 0 : a.front().descriptor.size();
  const auto sift =
      static_cast<std::size_t>(vision::descriptorBytes(vision::DescriptorType::kSift));
  const auto orb = static_cast<std::size_t>(vision::descriptorBytes(vision::DescriptorType::kOrb));
  const vision::DescriptorType type =
      bytes == orb ? vision::DescriptorType::kOrb : vision::DescriptorType::kSift;
  const bool descriptors =
      (bytes == sift || bytes == orb) && !b.empty() && b.front().descriptor.size() == bytes;
  if (!descriptors) {
    std::map<uint32_t, int> by_index;
    for (std::size_t i = 0; i < a.size(); ++i) by_index[a[i].index] = static_cast<int>(i);
    for (std::size_t j = 0; j < b.size(); ++j)
      if (auto it = by_index.find(b[j].index); it != by_index.end())
        pairs.emplace_back(it->second, static_cast<int>(j));
    return pairs;
  }
  auto features = [&](const std::vector<StereoObservation>& obs) {
    vision::Features f;
    f.type = type;
    f.descriptors.create(static_cast<int>(obs.size()), static_cast<int>(bytes), CV_8U);
    for (std::size_t i = 0; i < obs.size(); ++i) {
      f.keypoints.emplace_back(static_cast<float>(obs[i].z(0)), static_cast<float>(obs[i].z(1)),
                               1.0F);
      if (obs[i].descriptor.size() == bytes)
        std::copy(obs[i].descriptor.begin(), obs[i].descriptor.end(),
                  f.descriptors.ptr<uint8_t>(static_cast<int>(i)));
      else
        f.descriptors.row(static_cast<int>(i)).setTo(0);
    }
    return f;
  };
  const vision::Features query = features(b), train = features(a);
  std::vector<cv::Point2f> at;
  for (const auto& kp : query.keypoints) at.push_back(kp.pt);
  const auto candidates = vision::candidatesNear(at, train, o_.match_radius_px);
  for (const vision::Match& m : vision::matchDescriptors(query, train, o_.matching, &candidates))
    pairs.emplace_back(m.train, m.query);
  return pairs;
}

bool DynamicInitializer::fitMotion(const std::vector<Eigen::Vector3d>& prev,
                                   const std::vector<Eigen::Vector2d>& cur_px, Eigen::Matrix3d* R,
                                   Eigen::Vector3d* t, int* inliers) const {
  const int n = static_cast<int>(prev.size());
  if (n < o_.min_tracks) return false;
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (int i = 0; i < n; ++i) {
    object.emplace_back(prev[i].x(), prev[i].y(), prev[i].z());
    image.emplace_back(cur_px[i].x(), cur_px[i].y());
  }
  const StereoCameraOptions& c = camera_.options();
  const cv::Matx33d K(c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0);
  cv::Vec3d rvec, tvec;
  std::vector<int> in;
  cv::setRNGSeed(0x1D1A11);  // RANSAC draws: runs repeat exactly
  if (!cv::solvePnPRansac(object, image, K, cv::noArray(), rvec, tvec, false, o_.ransac_iterations,
                          static_cast<float>(o_.reprojection_error_px), 0.999, in,
                          cv::SOLVEPNP_EPNP))
    return false;
  if (static_cast<int>(in.size()) < o_.min_tracks) return false;
  // Refine on the inliers (Levenberg–Marquardt from the RANSAC solution).
  std::vector<cv::Point3d> object_in;
  std::vector<cv::Point2d> image_in;
  for (int i : in)
    object_in.push_back(object[static_cast<std::size_t>(i)]),
        image_in.push_back(image[static_cast<std::size_t>(i)]);
  cv::solvePnP(object_in, image_in, K, cv::noArray(), rvec, tvec, true, cv::SOLVEPNP_ITERATIVE);
  cv::Matx33d Rcv;
  cv::Rodrigues(rvec, Rcv);
  Eigen::Matrix3d R_curFromPrev;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) R_curFromPrev(r, k) = Rcv(r, k);
  const Eigen::Vector3d t_cur(tvec[0], tvec[1], tvec[2]);
  *R = R_curFromPrev.transpose();  // R_{C_prev←C_cur}
  *t = -R_curFromPrev.transpose() * t_cur;
  *inliers = static_cast<int>(in.size());
  return true;
}

void DynamicInitializer::addFrame(const StereoFrameObservations& observations) {
  Frame f;
  f.t_us = observations.t_us;
  f.observations = observations.observations;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const StereoObservation& o : f.observations) {
    Eigen::Vector3d p;
    f.p_inC.push_back(camera_.triangulateInCamera(o.z, &p).ok() ? p
                                                                : Eigen::Vector3d(nan, nan, nan));
  }
  const bool imu_covers = !imu_.empty() && imu_.front().t_us <= f.t_us;
  if (frames_.empty() || !imu_covers) {
    frames_.assign(1, std::move(f));
    return;
  }
  const Frame& prev = frames_.back();
  std::vector<Eigen::Vector3d> a;
  std::vector<Eigen::Vector2d> b;
  for (const auto& [i, j] : track(prev, f)) {
    const Eigen::Vector3d& p = prev.p_inC[static_cast<std::size_t>(i)];
    if (!p.allFinite() || p.z() > o_.max_depth) continue;
    a.push_back(p);
    b.push_back(f.observations[static_cast<std::size_t>(j)].z.head<2>());
  }
  Eigen::Matrix3d R;  // R_{C_prev←C_cur}
  Eigen::Vector3d t;
  if (!fitMotion(a, b, &R, &t, &f.inliers)) {
    frames_.assign(1, std::move(f));  // lost: start the window again here
    return;
  }
  f.R_C0toCk = prev.R_C0toCk * R;
  f.p_CkinC0 = prev.p_CkinC0 + prev.R_C0toCk * t;
  frames_.push_back(std::move(f));
  // Keep the window: drop frames older than window_s before the newest.
  while (frames_.size() > 2 &&
         frames_.back().t_us - frames_[1].t_us >= static_cast<int64_t>(o_.window_s * 1e6)) {
    frames_.erase(frames_.begin());
  }
}

bool DynamicInitializer::ready() const {
  return frames_.size() >= 3 &&
         frames_.back().t_us - frames_.front().t_us >= static_cast<int64_t>(o_.window_s * 1e6);
}

std::vector<ImuSample> DynamicInitializer::samplesBetween(int64_t t0, int64_t t1) const {
  // Samples bracketing [t0, t1], interpolated at both ends (same input model as the INS).
  std::vector<ImuSample> s;
  for (std::size_t i = 0; i + 1 < imu_.size(); ++i) {
    const ImuSample &a = imu_[i], &b = imu_[i + 1];
    if (b.t_us <= t0 || a.t_us >= t1) continue;
    if (s.empty()) s.push_back(a.t_us < t0 ? interpolateImu(a, b, t0) : a);
    s.push_back(b.t_us > t1 ? interpolateImu(a, b, t1) : b);
  }
  // A frame after the last sample (solve() bounds the hold by max_imu_hold_s): held to it.
  if (!imu_.empty() && imu_.back().t_us < t1 && imu_.back().t_us >= t0) {
    if (s.empty()) s.push_back(imu_.back());
    ImuSample held = imu_.back();
    held.t_us = t1;
    s.push_back(held);
  }
  return s;
}

Eigen::Matrix3d DynamicInitializer::integrateRotation(int64_t t0, int64_t t1,
                                                      const Eigen::Vector3d& gyro_bias) const {
  const std::vector<ImuSample> s = samplesBetween(t0, t1);
  Eigen::Matrix3d dR = Eigen::Matrix3d::Identity();
  for (std::size_t i = 0; i + 1 < s.size(); ++i) {
    const double dt = 1e-6 * static_cast<double>(s[i + 1].t_us - s[i].t_us);
    dR = dR * so3::exp<double>((0.5 * (s[i].gyro_B + s[i + 1].gyro_B) - gyro_bias) * dt);
  }
  return dR;
}

void DynamicInitializer::preintegrate(int64_t t0, int64_t t1, const Eigen::Vector3d& gyro_bias,
                                      Eigen::Vector3d* alpha, Eigen::Vector3d* beta) const {
  const std::vector<ImuSample> s = samplesBetween(t0, t1);
  Eigen::Matrix3d dR = Eigen::Matrix3d::Identity();
  alpha->setZero();
  beta->setZero();
  for (std::size_t i = 0; i + 1 < s.size(); ++i) {
    const double dt = 1e-6 * static_cast<double>(s[i + 1].t_us - s[i].t_us);
    const Eigen::Matrix3d dR1 =
        dR * so3::exp<double>((0.5 * (s[i].gyro_B + s[i + 1].gyro_B) - gyro_bias) * dt);
    const Eigen::Vector3d a = 0.5 * (dR * s[i].accel_B + dR1 * s[i + 1].accel_B);  // midpoint
    *alpha += *beta * dt + 0.5 * a * dt * dt;
    *beta += a * dt;
    dR = dR1;
  }
}

Eigen::Vector3d DynamicInitializer::gyroBias(const std::vector<Eigen::Matrix3d>& R_B0toBk,
                                             Eigen::Vector3d* sigma) const {
  // Gauss–Newton on r_k(b) = Log(ΔR_gyro,k(b)ᵀ ΔR_visual,k), Jacobian by central differences
  // (three columns, a handful of samples per pair: cheap).
  const int K = static_cast<int>(frames_.size()) - 1;
  auto residual = [&](const Eigen::Vector3d& b) {
    Eigen::VectorXd r(3 * K);
    for (int k = 0; k < K; ++k) {
      const Eigen::Matrix3d visual = R_B0toBk[k].transpose() * R_B0toBk[k + 1];
      const Eigen::Matrix3d gyro =
          integrateRotation(frames_[static_cast<std::size_t>(k)].t_us,
                            frames_[static_cast<std::size_t>(k + 1)].t_us, b);
      const Eigen::AngleAxisd e(gyro.transpose() * visual);
      r.segment<3>(3 * k) = e.angle() * e.axis();
    }
    return r;
  };
  constexpr double kStep = 1e-4;  // [rad/s]
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  Eigen::MatrixXd J(3 * K, 3);
  for (int iteration = 0; iteration < 3; ++iteration) {
    for (int i = 0; i < 3; ++i) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d(i) = kStep;
      J.col(i) = (residual(b + d) - residual(b - d)) / (2.0 * kStep);
    }
    b -= (J.transpose() * J).ldlt().solve(J.transpose() * residual(b));
  }
  const double s2 = residual(b).squaredNorm() / std::max(1, 3 * K - 3);
  *sigma = (s2 * (J.transpose() * J).inverse()).diagonal().cwiseSqrt();
  return b;
}

Expected<DynamicInitialization> DynamicInitializer::solve() const {
  if (!ready())
    return Status::Error("dynamic initialisation: " + std::to_string(frames_.size()) +
                         " tracked frames, not yet " + std::to_string(o_.window_s) + " s");
  const int64_t max_hold_us = std::llround(o_.max_imu_hold_s * 1e6);
  if (imu_.empty() || imu_.back().t_us + max_hold_us < frames_.back().t_us)
    return Status::Error("dynamic initialisation: the IMU does not cover the frames (last sample " +
                         std::to_string(imu_.empty() ? 0 : frames_.back().t_us - imu_.back().t_us) +
                         " µs before the last frame, more than max_imu_hold_s)");
  // Body poses in B_0 from the camera poses in C_0 (extrinsics R_BtoC, p_CinB).
  const Eigen::Matrix3d R_CtoB = camera_.options().R_BtoC.transpose();
  const Eigen::Vector3d& p_CinB = camera_.options().p_CinB;
  const int K = static_cast<int>(frames_.size()) - 1;
  std::vector<Eigen::Matrix3d> R(static_cast<std::size_t>(K + 1));
  std::vector<Eigen::Vector3d> p(static_cast<std::size_t>(K + 1));
  for (int k = 0; k <= K; ++k) {
    const Frame& f = frames_[static_cast<std::size_t>(k)];
    R[k] = R_CtoB * f.R_C0toCk * R_CtoB.transpose();
    p[k] = R_CtoB * (f.R_C0toCk * (-R_CtoB.transpose() * p_CinB) + f.p_CkinC0) + p_CinB;
  }
  Eigen::Vector3d gyro_bias_sigma;
  const Eigen::Vector3d gyro_bias = gyroBias(R, &gyro_bias_sigma);
  // Unknowns [v_0 … v_K | g] in B_0. Rows weighted by the noise they carry: visual relative
  // positions ≈ 1 cm, integrated accelerations ≈ 2 cm/s (vibration, noise over 50 ms).
  constexpr double kSigmaPosition = 0.01, kSigmaVelocity = 0.02;
  const int n = 3 * (K + 1) + 3, m = 6 * K, ig = 3 * (K + 1);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(m, n);
  Eigen::VectorXd b(m);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (int k = 0; k < K; ++k) {
    const int64_t t0 = frames_[static_cast<std::size_t>(k)].t_us;
    const int64_t t1 = frames_[static_cast<std::size_t>(k + 1)].t_us;
    const double dt = 1e-6 * static_cast<double>(t1 - t0);
    Eigen::Vector3d alpha, beta;
    preintegrate(t0, t1, gyro_bias, &alpha, &beta);
    const double wp = 1.0 / kSigmaPosition, wv = 1.0 / kSigmaVelocity;
    A.block<3, 3>(6 * k, 3 * k) = wp * dt * I;
    A.block<3, 3>(6 * k, ig) = wp * 0.5 * dt * dt * I;
    b.segment<3>(6 * k) = wp * (p[k + 1] - p[k] - R[k] * alpha);
    A.block<3, 3>(6 * k + 3, 3 * k) = -wv * I;
    A.block<3, 3>(6 * k + 3, 3 * (k + 1)) = wv * I;
    A.block<3, 3>(6 * k + 3, ig) = -wv * dt * I;
    b.segment<3>(6 * k + 3) = wv * R[k] * beta;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  if (qr.rank() < n) return Status::Error("dynamic initialisation: alignment is degenerate");
  const Eigen::VectorXd u = qr.solve(b);
  const Eigen::Vector3d g = u.segment<3>(ig);
  DynamicInitialization out;
  out.gravity_norm = g.norm();
  if (!std::isfinite(out.gravity_norm) ||
      std::abs(out.gravity_norm - gravity_) > o_.max_gravity_error)
    return Status::Error("dynamic initialisation: gravity solved as " +
                         std::to_string(out.gravity_norm) + " m/s², not " +
                         std::to_string(gravity_) + " (motion too weak or tracks wrong)");
  // Covariance of the free solution, scaled by the residual (the weights are guesses).
  const double dof = std::max(1, m - n);
  const double s2 = std::max(1.0, (A * u - b).squaredNorm() / dof);
  const Eigen::MatrixXd C = s2 * (A.transpose() * A).inverse();
  const Eigen::Vector3d g_dir = g / out.gravity_norm;
  const Eigen::Matrix3d tangent = I - g_dir * g_dir.transpose();
  const Eigen::Matrix3d C_tilt = tangent * C.block<3, 3>(ig, ig) * tangent;
  out.tilt_sigma = std::max(
      o_.tilt_sigma_min,
      std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(C_tilt).eigenvalues().maxCoeff()) /
          out.gravity_norm);
  out.velocity_sigma =
      std::max(o_.velocity_sigma_min, std::sqrt(C.block<3, 3>(3 * K, 3 * K).diagonal().maxCoeff()));
  // Velocities again with |g| fixed to the local gravity.
  const Eigen::VectorXd b_fixed = b - A.middleCols(ig, 3) * (gravity_ * g_dir);
  const Eigen::VectorXd v = A.leftCols(ig).colPivHouseholderQr().solve(b_fixed);

  // N: z along gravity (NED), heading 0 for the most horizontal body axis at the last frame.
  const Eigen::Matrix3d R_B0toN =
      Eigen::Quaterniond::FromTwoVectors(g_dir, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d R_BKtoN = R_B0toN * R[K];
  int axis = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(R_BKtoN(2, i)) < std::abs(R_BKtoN(2, axis))) axis = i;
  const double heading = std::atan2(R_BKtoN(1, axis), R_BKtoN(0, axis));
  const Eigen::Matrix3d Rz =
      Eigen::AngleAxisd(-heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  out.q_BtoN = Eigen::Quaterniond(Rz * R_BKtoN).normalized();
  out.v_N = Rz * R_B0toN * v.segment<3>(3 * K);
  out.t_us = frames_.back().t_us;
  out.gyro_bias = gyro_bias;
  out.gyro_bias_sigma = gyro_bias_sigma.cwiseMax(o_.gyro_bias_sigma_min);
  out.frames = K + 1;
  out.min_inliers = std::numeric_limits<int>::max();
  for (int k = 1; k <= K; ++k)
    out.min_inliers = std::min(out.min_inliers, frames_[static_cast<std::size_t>(k)].inliers);
  return out;
}

}  // namespace cvslam
