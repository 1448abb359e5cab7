// VisualInertialSlam::fuseCovarianceIntersection (docs/cooperation.md): the CI-consistent update on
// a small feature-level filter whose start was offset. Fusing accurate external estimates of its
// landmarks keeps the joint covariance PSD, moves the vehicle towards the truth through the
// vehicle–landmark correlations, and ω1 = 1 changes nothing.

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "coop_team_fixture.h"

namespace cvslam {
namespace {

TEST(CoopSlamFusion, CiUpdateCorrectsVehicleThroughCorrelations) {
  const std::unique_ptr<SimulatedTeamRun> run = cooptest::flyPairAlone(6.0, 5);
  ASSERT_NE(run, nullptr);
  const VisualInertialSlam& slam2 = run->slam(1);  // the agent with the offset start
  const Eigen::Vector3d p_true = run->simulator().agent(1).truth(slam2.time()).p_BinN;
  const double err_before = (slam2.vehicleState().head<3>() - p_true).norm();
  ASSERT_GT(err_before, 0.3) << "fixture: agent 2 should start offset";

  std::vector<int64_t> ids;
  std::vector<Eigen::Vector3d> truth;
  for (const StateLandmark& l : slam2.stateLandmarks()) {
    Eigen::Vector3d p;
    if (!run->sensing(1).landmarkTruth(l.id, &p)) continue;
    ids.push_back(l.id);
    truth.push_back(p);
    if (ids.size() == 6) break;
  }
  ASSERT_GE(ids.size(), 3u);
  const auto m = static_cast<Eigen::Index>(ids.size());
  Eigen::VectorXd y(3 * m);
  for (Eigen::Index i = 0; i < m; ++i) y.segment<3>(3 * i) = truth[static_cast<std::size_t>(i)];
  const double sigma = 0.05;
  const Eigen::MatrixXd R =
      static_cast<double>(m) * sigma * sigma * Eigen::MatrixXd::Identity(3 * m, 3 * m);

  VisualInertialSlam same = slam2;
  ASSERT_TRUE(same.fuseCovarianceIntersection(ids, y, R, 1.0).ok());
  EXPECT_EQ(same.state().mean(), slam2.state().mean());
  EXPECT_EQ(same.state().covariance(), slam2.state().covariance());

  VisualInertialSlam fused = slam2;
  ASSERT_TRUE(fused.fuseCovarianceIntersection(ids, y, R, 0.3).ok());
  const double err_after = (fused.vehicleState().head<3>() - p_true).norm();
  EXPECT_LT(err_after, 0.5 * err_before) << "before " << err_before << " after " << err_after;
  const Eigen::MatrixXd& P = fused.state().covariance();
  EXPECT_LT((P - P.transpose()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P).eigenvalues().minCoeff(), -1e-12);
  // The fused landmarks are close to the external estimates.
  for (const StateLandmark& l : fused.stateLandmarks()) {
    for (std::size_t i = 0; i < ids.size(); ++i) {
      if (l.id == ids[i]) {
        EXPECT_LT((l.p_LinN - truth[i]).norm(), 0.3);
      }
    }
  }

  VisualInertialSlam bad = slam2;
  EXPECT_FALSE(bad.fuseCovarianceIntersection(ids, y, R, 0.0).ok());
  EXPECT_FALSE(bad.fuseCovarianceIntersection({int64_t{1} << 50}, Eigen::Vector3d::Zero(),
                                              Eigen::Matrix3d::Identity(), 0.5)
                   .ok());
  EXPECT_FALSE(bad.fuseCovarianceIntersection(ids, y.head(3), R, 0.5).ok());
}

}  // namespace
}  // namespace cvslam
