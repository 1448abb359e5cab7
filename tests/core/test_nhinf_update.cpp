// Nonlinear H∞ update (thesis §3.6.5, docs/conventions.md) against the EKF and the dense formulas.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <random>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/io/config_node.h"
#include "filter_fixtures.h"

namespace cvslam {
namespace {

Eigen::VectorXd eigenvalues(const Eigen::MatrixXd& P) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P, Eigen::EigenvaluesOnly).eigenvalues();
}

UpdatePolicy nhinfPolicy(double theta, double cv2 = 1.0, double margin = 0.9) {
  UpdatePolicy p;
  p.theta = theta;
  p.measurement_noise_scale = cv2;
  p.theta_margin = margin;
  p.theta_weighting = ThetaWeighting::kIdentity;  // the literal eq. 3.39 with S = I
  return p;
}

UpdatePolicy observedPolicy(double theta, double margin = 0.9) {
  UpdatePolicy p = nhinfPolicy(theta, 1.0, margin);
  p.theta_weighting = ThetaWeighting::kObserved;
  return p;
}

/// Orthogonal projector onto the range of Hᵀ.
Eigen::MatrixXd rowSpaceProjector(const Eigen::MatrixXd& H) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(H, Eigen::ComputeFullV);
  const Eigen::Index r = svd.rank();
  const Eigen::MatrixXd V = svd.matrixV().leftCols(r);
  return V * V.transpose();
}

struct Fixture {
  SlamState prior;
  MeasurementBatch batch;
  explicit Fixture(unsigned seed, int landmarks = 6, int observations = 5) {
    std::mt19937 rng(seed);
    prior = test::randomSlamState(landmarks, rng);
    test::randomStereoBatch(prior, observations, rng, &batch, 2.0);
  }
};

TEST(NhinfUpdate, ThetaZeroReproducesTheEkf) {
  Fixture f(11, 24, 20);
  SlamState ekf = f.prior, zero = f.prior, tiny = f.prior;
  ASSERT_TRUE(CovarianceHelper::update(ekf, f.batch, UpdatePolicy::ekf(), nullptr).ok());
  ASSERT_TRUE(CovarianceHelper::update(zero, f.batch, nhinfPolicy(0.0), nullptr).ok());
  EXPECT_EQ(zero.mean(), ekf.mean());
  EXPECT_EQ(zero.covariance(), ekf.covariance());
  // θ → 0 through the information-form branch.
  UpdateReport report;
  ASSERT_TRUE(CovarianceHelper::update(tiny, f.batch, nhinfPolicy(1e-12), &report).ok());
  EXPECT_FALSE(report.theta_reduced);
  EXPECT_DOUBLE_EQ(report.theta_used, 1e-12);
  EXPECT_LT((tiny.mean() - ekf.mean()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((tiny.covariance() - ekf.covariance()).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(NhinfUpdate, PosteriorEqualsDenseInformationForm) {
  // P⁺ = (P⁻¹ + Hᵀ (c_v² R)⁻¹ H − θ I)⁻¹ and x⁺ = x + P Hᵀ (H P Hᵀ + c_v² R)⁻¹ r.
  Fixture f(12);
  const double theta = 0.5, cv2 = 0.8;
  SlamState s = f.prior;
  UpdateReport report;
  ASSERT_TRUE(CovarianceHelper::update(s, f.batch, nhinfPolicy(theta, cv2, 1.0), &report).ok());
  ASSERT_FALSE(report.theta_reduced);
  const Eigen::MatrixXd& P = f.prior.covariance();
  const Eigen::MatrixXd H = f.batch.H();
  const Eigen::MatrixXd R = cv2 * f.batch.R();
  const int n = f.prior.size();
  const Eigen::MatrixXd info =
      P.inverse() + H.transpose() * R.inverse() * H - theta * Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd expected_P = info.inverse();
  EXPECT_TRUE(s.covariance().isApprox(expected_P, 1e-8));
  const Eigen::VectorXd expected_x = f.prior.mean() + P * H.transpose() *
                                                          (H * P * H.transpose() + R).inverse() *
                                                          f.batch.residual();
  // Angles are wrapped after the update; the fixture stays far from ±π.
  EXPECT_TRUE(s.mean().isApprox(expected_x, 1e-10));
}

TEST(NhinfUpdate, ObservedWeightingEqualsDenseProjectedForm) {
  // S = Π: P⁺ = (P⁻¹ + Hᵀ R⁻¹ H − θ Π)⁻¹ with Π the projector onto range(Hᵀ).
  Fixture f(21);
  const double theta = 0.5;
  SlamState s = f.prior;
  UpdateReport report;
  ASSERT_TRUE(CovarianceHelper::update(s, f.batch, observedPolicy(theta, 1.0), &report).ok());
  ASSERT_FALSE(report.theta_reduced);
  const Eigen::MatrixXd& P = f.prior.covariance();
  const Eigen::MatrixXd H = f.batch.H();
  const Eigen::MatrixXd info =
      P.inverse() + H.transpose() * f.batch.R().inverse() * H - theta * rowSpaceProjector(H);
  EXPECT_TRUE(s.covariance().isApprox(info.inverse(), 1e-8));
}

TEST(NhinfUpdate, ObservedWeightingLeavesUnobservedDirectionsToTheEkf) {
  // Directions with H g = 0 (SLAM's gauge, unobserved landmarks) keep the EKF information,
  // while S = I removes θ from them at every update.
  Fixture f(22, 8, 4);
  const Eigen::MatrixXd H = f.batch.H();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(H, Eigen::ComputeFullV);
  ASSERT_LT(svd.rank(), H.cols());
  const Eigen::VectorXd g = svd.matrixV().col(H.cols() - 1);  // in the null space of H
  ASSERT_LT((H * g).norm(), 1e-9);
  SlamState ekf = f.prior, observed = f.prior, identity = f.prior;
  ASSERT_TRUE(CovarianceHelper::update(ekf, f.batch, UpdatePolicy::ekf(), nullptr).ok());
  ASSERT_TRUE(CovarianceHelper::update(observed, f.batch, observedPolicy(0.2), nullptr).ok());
  ASSERT_TRUE(CovarianceHelper::update(identity, f.batch, nhinfPolicy(0.2), nullptr).ok());
  const auto information = [&](const SlamState& st) {
    return g.dot(st.covariance().ldlt().solve(g));
  };
  EXPECT_NEAR(information(observed), information(ekf), 1e-8 * information(ekf));
  EXPECT_NEAR(information(identity), information(ekf) - 0.2, 1e-6 * information(ekf));
  // Observed directions are still inflated (more conservative than the EKF).
  EXPECT_GT((observed.covariance() - ekf.covariance()).trace(), 0.0);
}

TEST(NhinfUpdate, ObservedWeightingWithVanishingThetaIsTheEkf) {
  Fixture f(23, 24, 20);
  SlamState ekf = f.prior, tiny = f.prior;
  ASSERT_TRUE(CovarianceHelper::update(ekf, f.batch, UpdatePolicy::ekf(), nullptr).ok());
  ASSERT_TRUE(CovarianceHelper::update(tiny, f.batch, observedPolicy(1e-12), nullptr).ok());
  EXPECT_LT((tiny.mean() - ekf.mean()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((tiny.covariance() - ekf.covariance()).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(NhinfUpdate, IsMoreConservativeThanTheEkf) {
  for (unsigned seed : {13u, 14u, 15u}) {
    Fixture f(seed, 24, 20);
    SlamState ekf = f.prior, hinf = f.prior;
    ASSERT_TRUE(CovarianceHelper::update(ekf, f.batch, UpdatePolicy::ekf(), nullptr).ok());
    UpdateReport report;
    ASSERT_TRUE(CovarianceHelper::update(hinf, f.batch, nhinfPolicy(0.5), &report).ok());
    ASSERT_FALSE(report.theta_reduced);
    const Eigen::VectorXd d = eigenvalues(hinf.covariance() - ekf.covariance());
    EXPECT_GT(d.minCoeff(), -1e-12) << "P_NH∞ − P_EKF must be positive semi-definite";
    EXPECT_GT(d.maxCoeff(), 1e-6) << "and not equal";
    EXPECT_GT(eigenvalues(hinf.covariance()).minCoeff(), 0.0);
    // Same gain: the means agree (both use the prior covariance).
    EXPECT_TRUE(hinf.mean().isApprox(ekf.mean(), 1e-12));
  }
}

TEST(NhinfUpdate, FallbackReducesThetaWhenEq340FailsAndIsCounted) {
  Fixture f(16, 24, 20);
  const double lambda_max = eigenvalues([&] {
                              SlamState e = f.prior;
                              CovarianceHelper::update(e, f.batch, UpdatePolicy::ekf(), nullptr);
                              return e.covariance();
                            }())
                                .maxCoeff();
  FilterStatistics stats;
  // Admissible θ: no fallback.
  SlamState ok = f.prior;
  UpdateReport report;
  ASSERT_TRUE(CovarianceHelper::update(ok, f.batch, nhinfPolicy(0.5 / lambda_max), &report).ok());
  stats.add(report);
  EXPECT_FALSE(report.theta_reduced);
  // θ λ_max = 2: (P⁻¹ + HᵀR⁻¹H − θI) is indefinite (eq. 3.40 fails).
  SlamState s = f.prior;
  const double theta = 2.0 / lambda_max;
  ASSERT_TRUE(CovarianceHelper::update(s, f.batch, nhinfPolicy(theta), &report).ok());
  stats.add(report);
  EXPECT_TRUE(report.theta_reduced);
  EXPECT_LT(report.theta_used, theta);
  EXPECT_NEAR(report.theta_used * lambda_max, 0.45, 1e-9);  // half the margin of 0.9
  EXPECT_GT(eigenvalues(s.covariance()).minCoeff(), 0.0);
  EXPECT_EQ(stats.updates, 2);
  EXPECT_EQ(stats.theta_reductions, 1);
  // The margin alone can trigger it too: θ λ_max = 0.95 satisfies eq. 3.40 but not 0.9.
  s = f.prior;
  ASSERT_TRUE(CovarianceHelper::update(s, f.batch, nhinfPolicy(0.95 / lambda_max), &report).ok());
  EXPECT_TRUE(report.theta_reduced);
  s = f.prior;
  ASSERT_TRUE(
      CovarianceHelper::update(s, f.batch, nhinfPolicy(0.95 / lambda_max, 1.0, 1.0), &report).ok());
  EXPECT_FALSE(report.theta_reduced);
}

TEST(FilterOptions, LoadsValidatesAndBuildsThePolicy) {
  auto cfg = ConfigNode::fromString(
      "filter: {type: nhinf, gamma: 2.0, delta1: 0.1, delta2: 0.5, delta3: 0.2,"
      " gate_probability: 0.99}",
      "agent.yaml");
  ASSERT_TRUE(cfg.ok());
  FilterOptions o;
  ASSERT_TRUE(o.load(cfg->child("filter")).ok()) << cfg->status().message();
  EXPECT_TRUE(cfg->finish().ok());
  const auto policy = o.policy();
  ASSERT_TRUE(policy.ok());
  const double cv2 = 1.0 - 4.0 * (0.01 + 0.04);  // eq. 3.58
  EXPECT_DOUBLE_EQ(policy->theta, 0.25);
  EXPECT_DOUBLE_EQ(policy->measurement_noise_scale, cv2);
  EXPECT_DOUBLE_EQ(policy->process_noise_scale, cv2 / 1.25);
  EXPECT_DOUBLE_EQ(policy->gate_probability, 0.99);
  auto printed = ConfigNode::fromString(o.print(), "printed");
  ASSERT_TRUE(printed.ok()) << o.print();
  FilterOptions back;
  ASSERT_TRUE(back.load(*printed).ok());
  EXPECT_TRUE(printed->finish().ok());
  EXPECT_EQ(back.print(), o.print());
  EXPECT_EQ(back.type, FilterType::kNhinf);

  FilterOptions ekf;
  const auto ekf_policy = ekf.policy();
  ASSERT_TRUE(ekf_policy.ok());
  EXPECT_EQ(ekf_policy->theta, 0.0);
  EXPECT_EQ(ekf_policy->measurement_noise_scale, 1.0);

  // c_v² ≤ 0: γ too large for the deltas.
  auto bad = ConfigNode::fromString("{type: nhinf, gamma: 10, delta1: 0.1}", "agent.yaml");
  FilterOptions b;
  const Status s = b.load(*bad);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("c_v²"), std::string::npos) << s.message();
  for (const char* yaml : {"{gamma: 0}", "{delta2: -1}", "{theta_margin: 1.5}",
                           "{gate_probability: 1}", "{type: kalman}"}) {
    auto c = ConfigNode::fromString(yaml, "t.yaml");
    FilterOptions x;
    EXPECT_FALSE(x.load(*c).ok()) << yaml;
  }
}

}  // namespace
}  // namespace cvslam
