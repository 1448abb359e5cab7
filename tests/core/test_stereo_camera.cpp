#include "cvslam/camera/stereo_camera.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <random>
#include <vector>

#include "cvslam/geometry/euler.h"
#include "cvslam/io/config_node.h"
#include "jacobian_check.h"

namespace cvslam {
namespace {

StereoCameraOptions skewedRig() {
  // A rig that is not axis aligned and off the body origin, so that every Jacobian block
  // is exercised (the default rig has p_CinB = 0).
  StereoCameraOptions o;
  o.fx = 458.0;
  o.fy = 457.0;
  o.cx = 367.0;
  o.cy = 248.0;
  o.width = 752;
  o.height = 480;
  o.baseline = 0.11;
  o.R_BtoC = (Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()) *
              Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY()) *
              Eigen::AngleAxisd(1.5, Eigen::Vector3d::UnitZ()))
                 .toRotationMatrix();
  o.p_CinB = {0.1, -0.05, 0.2};
  return o;
}

struct Case {
  StereoCamera::Vector9d x_v;
  Eigen::Vector3d p_LinN;
};

/// Vehicle states at several attitudes with a landmark in front of the cameras.
std::vector<Case> cases(const StereoCamera& cam) {
  std::vector<Case> out;
  const std::vector<Eigen::Vector3d> eulers = {
      {0, 0, 0}, {0.1, -0.2, 0.3}, {-0.4, 0.3, 2.5}, {0.7, -0.6, -1.2}, {0.05, 1.2, -3.0}};
  const std::vector<Eigen::Vector3d> in_camera = {{0.3, -0.2, 4.0}, {-1.0, 0.5, 8.0}};
  int k = 0;
  for (const auto& e : eulers) {
    for (const auto& pC : in_camera) {
      Case c;
      c.x_v << 10.0 + k, -3.0 + 0.5 * k, -20.0 - k, 1, 2, 3, e;
      // Place the landmark from a camera-frame point through the rig and the attitude, so
      // it is in front of the cameras whatever the attitude.
      c.p_LinN =
          c.x_v.head<3>() + rotationBodyToNav(Eigen::Vector3d(e)) *
                                (cam.options().R_BtoC.transpose() * pC + cam.options().p_CinB);
      out.push_back(c);
      ++k;
    }
  }
  return out;
}

TEST(StereoCamera, ProjectKnownPoint) {
  StereoCameraOptions o;
  o.R_BtoC.setIdentity();
  const StereoCamera cam(o);
  const Eigen::Vector4d z = cam.project(Eigen::Vector3d(1.0, 0.5, 10.0));
  EXPECT_NEAR(z(0), 560.0 * 0.1 + 160.0, 1e-12);
  EXPECT_NEAR(z(1), 560.0 * 0.05 + 120.0, 1e-12);
  EXPECT_NEAR(z(2), 560.0 * 0.08 + 160.0, 1e-12);  // disparity f b / z = 11.2 px
  EXPECT_NEAR(z(3), z(1), 1e-12);
}

TEST(StereoCamera, JacobianCameraFrame) {
  const StereoCamera cam(skewedRig());
  for (const Eigen::Vector3d& pC : {Eigen::Vector3d(0.3, -0.2, 4.0), Eigen::Vector3d(-2, 1, 7)}) {
    StereoCamera::Matrix4x3d dz_dpC;
    cam.project(pC, &dz_dpC);
    EXPECT_TRUE(test::jacobianMatches(
        [&](const Eigen::VectorXd& p) -> Eigen::VectorXd {
          return cam.project(Eigen::Vector3d(p));
        },
        pC, dz_dpC));
  }
}

TEST(StereoCamera, JacobiansOfTheObservationModel) {
  const StereoCamera cam(skewedRig());
  for (const Case& c : cases(cam)) {
    StereoCamera::Matrix4x9d dz_dxv;
    StereoCamera::Matrix4x3d dz_dpL;
    const Eigen::Vector4d z = cam.project(c.x_v, c.p_LinN, &dz_dxv, &dz_dpL);
    EXPECT_TRUE(z.allFinite());
    EXPECT_TRUE((dz_dxv.block<4, 3>(0, 3).isZero())) << "velocity does not enter eq. 5.20";
    EXPECT_TRUE(test::jacobianMatches(
        [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
          return cam.project(StereoCamera::Vector9d(x), c.p_LinN);
        },
        c.x_v, dz_dxv, 1e-5, 1e-5));
    EXPECT_TRUE(test::jacobianMatches(
        [&](const Eigen::VectorXd& p) -> Eigen::VectorXd {
          return cam.project(c.x_v, Eigen::Vector3d(p));
        },
        c.p_LinN, dz_dpL, 1e-5, 1e-5));
  }
}

TEST(StereoCamera, JacobiansOfTheInverseModel) {
  const StereoCamera cam(skewedRig());
  for (const Case& c : cases(cam)) {
    const Eigen::Vector4d z = cam.project(c.x_v, c.p_LinN);
    Eigen::Vector3d p;
    StereoCamera::Matrix3x9d dpL_dxv;
    StereoCamera::Matrix3x4d dpL_dz;
    ASSERT_TRUE(cam.triangulate(z, c.x_v, &p, &dpL_dxv, &dpL_dz).ok());
    const auto tri = [&](const Eigen::Vector4d& zz, const StereoCamera::Vector9d& xx) {
      Eigen::Vector3d out;
      EXPECT_TRUE(cam.triangulate(zz, xx, &out).ok());
      return out;
    };
    EXPECT_TRUE(test::jacobianMatches(
        [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
          return tri(z, StereoCamera::Vector9d(x));
        },
        c.x_v, dpL_dxv, 1e-5, 1e-5));
    EXPECT_TRUE(test::jacobianMatches(
        [&](const Eigen::VectorXd& zz) -> Eigen::VectorXd {
          return tri(Eigen::Vector4d(zz), c.x_v);
        },
        z, dpL_dz, 1e-5, 1e-5));
    StereoCamera::Matrix3x4d dpC_dz;
    Eigen::Vector3d pC;
    ASSERT_TRUE(cam.triangulateInCamera(z, &pC, &dpC_dz).ok());
    EXPECT_TRUE(test::jacobianMatches(
        [&](const Eigen::VectorXd& zz) -> Eigen::VectorXd {
          Eigen::Vector3d out;
          EXPECT_TRUE(cam.triangulateInCamera(Eigen::Vector4d(zz), &out).ok());
          return out;
        },
        z, dpC_dz, 1e-5, 1e-5));
  }
}

TEST(StereoCamera, TriangulateInvertsProject) {
  const StereoCamera cam(skewedRig());
  for (const Case& c : cases(cam)) {
    const Eigen::Vector4d z = cam.project(c.x_v, c.p_LinN);
    Eigen::Vector3d p;
    ASSERT_TRUE(cam.triangulate(z, c.x_v, &p).ok());
    EXPECT_LT((p - c.p_LinN).norm(), 1e-9 * (1.0 + c.p_LinN.norm()));
    // And the other way round: project(triangulate(z)) == z.
    EXPECT_LT((cam.project(c.x_v, p) - z).norm(), 1e-8);
  }
}

TEST(StereoCamera, TriangulateRejectsBadDisparity) {
  const StereoCamera cam(skewedRig());
  const StereoCamera::Vector9d x_v = StereoCamera::Vector9d::Zero();
  Eigen::Vector3d p(7, 7, 7);
  const Status zero = cam.triangulate({100, 50, 100, 50}, x_v, &p);
  EXPECT_FALSE(zero.ok());
  EXPECT_NE(zero.message().find("disparity"), std::string::npos) << zero.message();
  EXPECT_FALSE(cam.triangulate({100, 50, 101, 50}, x_v, &p).ok());  // negative
  EXPECT_FALSE(cam.triangulate({NAN, 50, 90, 50}, x_v, &p).ok());
  EXPECT_EQ(p, Eigen::Vector3d(7, 7, 7)) << "outputs untouched on failure";
  EXPECT_TRUE(cam.triangulate({100, 50, 90, 50}, x_v, &p).ok());
}

// The first-order triangulation covariance J_z R J_zᵀ must match the scatter of triangulated
// points when the pixels carry small Gaussian noise (GTSAM-style Monte-Carlo check). This is
// what the filter uses to initialise P_LL, so a wrong Jacobian gives an inconsistent map.
TEST(StereoCamera, TriangulationCovarianceMatchesMonteCarlo) {
  const StereoCamera cam(skewedRig());
  StereoCamera::Vector9d x_v;
  x_v << 5, 2, -30, 0, 0, 0, 0.1, -0.05, 0.7;
  const Eigen::Vector3d p_LinC(0.5, -0.3, 5.0);  // disparity ≈ 10 px
  const Eigen::Vector4d z = cam.project(p_LinC);
  Eigen::Vector3d p0;
  StereoCamera::Matrix3x4d J_z;
  ASSERT_TRUE(cam.triangulate(z, x_v, &p0, nullptr, &J_z).ok());
  const double sigma_px = 0.05;
  const Eigen::Matrix3d P = J_z * (sigma_px * sigma_px) * J_z.transpose();

  std::mt19937 rng(42);
  std::normal_distribution<double> n(0.0, sigma_px);
  const int kSamples = 20000;
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  double nees = 0.0;
  const Eigen::Matrix3d P_inv = P.inverse();
  for (int i = 0; i < kSamples; ++i) {
    const Eigen::Vector4d zn = z + Eigen::Vector4d(n(rng), n(rng), n(rng), n(rng));
    Eigen::Vector3d p;
    ASSERT_TRUE(cam.triangulate(zn, x_v, &p).ok());
    const Eigen::Vector3d e = p - p0;
    S += e * e.transpose();
    nees += e.dot(P_inv * e);
  }
  S /= kSamples;
  nees /= kSamples;
  // Sample covariance within a few percent of the linearised one (sampling error ≈ 1–2 %).
  for (int r = 0; r < 3; ++r) {
    EXPECT_NEAR(S(r, r), P(r, r), 0.05 * P(r, r)) << "axis " << r;
  }
  EXPECT_NEAR(nees, 3.0, 0.15);
}

// Landmark augmentation with an uncertain vehicle (docs/conventions.md): the sampled landmark
// covariance and its cross-covariance with the vehicle match
//   P_LL = J_x P_vv J_xᵀ + J_z R J_zᵀ,  P_Lx = J_x P_vv.
TEST(StereoCamera, AugmentationCovarianceMatchesMonteCarlo) {
  const StereoCamera cam(skewedRig());
  StereoCamera::Vector9d x_v;
  x_v << 5, 2, -30, 1, 0, 0, 0.1, -0.05, 0.7;
  const Eigen::Vector4d z = cam.project(Eigen::Vector3d(0.5, -0.3, 5.0));
  Eigen::Vector3d p0;
  StereoCamera::Matrix3x9d J_x;
  StereoCamera::Matrix3x4d J_z;
  ASSERT_TRUE(cam.triangulate(z, x_v, &p0, &J_x, &J_z).ok());
  StereoCamera::Vector9d sigma_v;
  sigma_v << 0.05, 0.05, 0.05, 0.1, 0.1, 0.1, 0.005, 0.005, 0.005;
  const Eigen::Matrix<double, 9, 9> P_vv = sigma_v.cwiseAbs2().asDiagonal();
  const double sigma_px = 0.05;
  const Eigen::Matrix3d P_LL =
      J_x * P_vv * J_x.transpose() + J_z * (sigma_px * sigma_px) * J_z.transpose();
  const StereoCamera::Matrix3x9d P_Lx = J_x * P_vv;

  std::mt19937 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  const int kSamples = 20000;
  Eigen::Matrix3d S_LL = Eigen::Matrix3d::Zero();
  StereoCamera::Matrix3x9d S_Lx = StereoCamera::Matrix3x9d::Zero();
  for (int i = 0; i < kSamples; ++i) {
    StereoCamera::Vector9d dx;
    for (int k = 0; k < 9; ++k) dx(k) = sigma_v(k) * n01(rng);
    Eigen::Vector4d dz;
    for (int k = 0; k < 4; ++k) dz(k) = sigma_px * n01(rng);
    Eigen::Vector3d p;
    ASSERT_TRUE(cam.triangulate(z + dz, x_v + dx, &p).ok());
    S_LL += (p - p0) * (p - p0).transpose();
    S_Lx += (p - p0) * dx.transpose();
  }
  S_LL /= kSamples;
  S_Lx /= kSamples;
  for (int r = 0; r < 3; ++r) EXPECT_NEAR(S_LL(r, r), P_LL(r, r), 0.05 * P_LL(r, r));
  // Cross-covariance: compare against the scale of its own entries (many are near zero).
  EXPECT_LT((S_Lx - P_Lx).norm(), 0.05 * P_Lx.norm());
}

TEST(StereoCamera, MinDisparityOptionLoads) {
  auto cfg = ConfigNode::fromString("{min_disparity: -1}", "cam.yaml");
  ASSERT_TRUE(cfg.ok());
  StereoCameraOptions o;
  const Status s = o.load(*cfg);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("min_disparity"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace cvslam
