#include "cvslam/filter/chi_square.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace cvslam {
namespace {

TEST(ChiSquare, QuantileMatchesTables) {
  // Reference values (R: qchisq(p, k)).
  struct Row {
    double p;
    int dof;
    double x;
  };
  for (const Row& r : {Row{0.95, 1, 3.841458820694124}, Row{0.999, 1, 10.82756617046},
                       Row{0.99, 2, 9.210340371976184}, Row{0.95, 3, 7.814727903251178},
                       Row{0.95, 4, 9.487729036781154}, Row{0.999, 4, 18.46682695290317},
                       Row{0.99, 6, 16.81189383504116}, Row{0.999, 8, 26.12448155837614},
                       Row{0.5, 4, 3.356693980033322}, Row{0.05, 4, 0.7107230213973239},
                       Row{0.999, 80, 124.8392}}) {
    EXPECT_NEAR(chiSquareQuantile(r.p, r.dof), r.x, 1e-9 * r.x + 1e-4 * (r.dof == 80))
        << "p=" << r.p << " dof=" << r.dof;
    EXPECT_NEAR(chiSquareCdf(chiSquareQuantile(r.p, r.dof), r.dof), r.p, 1e-12);
  }
  EXPECT_TRUE(std::isnan(chiSquareQuantile(1.0, 4)));
  EXPECT_TRUE(std::isnan(chiSquareQuantile(0.9, 0)));
}

TEST(ChiSquare, WilsonHilfertyIsCloseForGatingDof) {
  EXPECT_NEAR(chiSquareQuantileWilsonHilferty(0.999, 4), 18.4668, 0.02 * 18.4668);
  EXPECT_NEAR(chiSquareQuantileWilsonHilferty(0.95, 4), 9.4877, 0.01 * 9.4877);
}

TEST(ChiSquare, NormalQuantile) {
  EXPECT_NEAR(normalQuantile(0.5), 0.0, 1e-15);
  EXPECT_NEAR(normalQuantile(0.975), 1.959963984540054, 1e-12);
  EXPECT_NEAR(normalQuantile(0.001), -3.090232306167813, 1e-12);
  EXPECT_NEAR(normalQuantile(1e-10), -6.361340902404056, 1e-9);
}

TEST(ChiSquare, SampledSquaredNormsFollowTheCdf) {
  // The fraction of χ²_4 samples below the 0.95 quantile is 0.95 (binomial 5σ bound).
  std::mt19937 rng(7);
  std::normal_distribution<double> n;
  const double gate = chiSquareQuantile(0.95, 4);
  constexpr int kSamples = 20000;
  int inside = 0;
  for (int i = 0; i < kSamples; ++i) {
    double s = 0;
    for (int k = 0; k < 4; ++k) s += std::pow(n(rng), 2);
    inside += s <= gate;
  }
  EXPECT_NEAR(static_cast<double>(inside) / kSamples, 0.95,
              5.0 * std::sqrt(0.95 * 0.05 / kSamples));
}

}  // namespace
}  // namespace cvslam
