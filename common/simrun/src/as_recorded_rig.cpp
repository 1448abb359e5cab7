#include "cvslam/simrun/as_recorded_rig.h"

#include <Eigen/SVD>

namespace cvslam {

namespace {

// Nearest rotation (calibration files carry rotations to a few digits only).
Eigen::Matrix3d orthonormalised(const Eigen::Matrix3d& R) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

// Camera pose in N from the vehicle pose and the camera's T_BS (camera → S).
void cameraPose(const VehiclePose& truth, const Eigen::Matrix3d& R_BtoS,
                const EurocCameraCalibration& c, Eigen::Matrix3d* R_NtoC, Eigen::Vector3d* p_CinN) {
  const Eigen::Matrix3d R_StoN = truth.q_BtoN.toRotationMatrix() * R_BtoS.transpose();
  const Eigen::Matrix3d R_CtoS = orthonormalised(c.R_CtoB());
  *R_NtoC = (R_StoN * R_CtoS).transpose();
  *p_CinN = truth.p_BinN + R_StoN * c.p_CinB();
}

}  // namespace

Expected<AsRecordedRig> AsRecordedRig::create(std::shared_ptr<const render::World> world,
                                              const EurocStereoCalibration& rig,
                                              const StereoCameraOptions& scenario_camera,
                                              const render::RenderOptions& rendering) {
  AsRecordedRig r;
  r.rig_ = rig;
  r.R_BtoS_ = orthonormalised(orthonormalised(rig.left.R_CtoB()) * scenario_camera.R_BtoC);
  auto left = render::DistortedCameraRenderer::create(world, rig.left, rendering);
  if (!left.ok()) return left.status();
  auto right = render::DistortedCameraRenderer::create(world, rig.right, rendering);
  if (!right.ok()) return right.status();
  r.left_ = std::make_shared<const render::DistortedCameraRenderer>(std::move(*left));
  r.right_ = std::make_shared<const render::DistortedCameraRenderer>(std::move(*right));
  return r;
}

ImuSample AsRecordedRig::imu(const ImuSample& body) const {
  ImuSample s = body;
  s.gyro_B = R_BtoS_ * body.gyro_B;
  s.accel_B = R_BtoS_ * body.accel_B;
  return s;
}

EurocGroundTruth AsRecordedRig::groundTruth(int64_t t_us, const VehiclePose& truth) const {
  EurocGroundTruth g;
  g.t_ns = t_us * 1000;
  g.p_SinR = R_NtoW() * truth.p_BinN;
  g.q_StoR = Eigen::Quaterniond(R_NtoW() * truth.q_BtoN.toRotationMatrix() * R_BtoS_.transpose());
  g.q_StoR.normalize();
  g.v_SinR = R_NtoW() * truth.v_N;
  g.gyro_bias = R_BtoS_ * truth.gyro_bias;
  g.accel_bias = R_BtoS_ * truth.accel_bias;
  return g;
}

void AsRecordedRig::render(const VehiclePose& truth, uint64_t frame_index, cv::Mat* left,
                           cv::Mat* right) const {
  Eigen::Matrix3d R_NtoC;
  Eigen::Vector3d p_CinN;
  cameraPose(truth, R_BtoS_, rig_.left, &R_NtoC, &p_CinN);
  *left = left_->render(R_NtoC, p_CinN, 2 * frame_index);
  cameraPose(truth, R_BtoS_, rig_.right, &R_NtoC, &p_CinN);
  *right = right_->render(R_NtoC, p_CinN, 2 * frame_index + 1);
}

EurocCameraInfo AsRecordedRig::cameraInfo(bool right, double rate_hz) const {
  const EurocCameraCalibration& c = right ? rig_.right : rig_.left;
  EurocCameraInfo info;
  info.comment = c.comment.empty() ? "cvslam as-recorded camera" : c.comment;
  info.T_BS = c.T_CtoB;
  info.rate_hz = rate_hz;
  info.width = c.width;
  info.height = c.height;
  info.intrinsics = c.intrinsics;
  info.distortion_model = c.distortion_model;
  info.distortion = {c.distortion(0), c.distortion(1), c.distortion(2), c.distortion(3)};
  return info;
}

}  // namespace cvslam
