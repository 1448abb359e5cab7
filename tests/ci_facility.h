#pragma once
// A test that needs a facility the host may lack (java, matplotlib, a built tool): skipped
// where it is missing, except under CI (CI=true in the environment), where the facility is
// part of the machine (scripts/setup.sh installs it) and its absence fails the test.
//   if (!have_java) CVSLAM_SKIP_UNLESS_CI() << "needs java";

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>

namespace cvslam::test {

inline bool underCi() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::strcmp(ci, "true") == 0;
}

}  // namespace cvslam::test

// A statement (use it as `CVSLAM_SKIP_UNLESS_CI() << "why";`): GTEST_SKIP() outside CI, a
// fatal failure under CI=true; returns from the test either way (as GTEST_SKIP does).
#define CVSLAM_SKIP_UNLESS_CI()                                                           \
  return ::testing::internal::AssertHelper(                                               \
             ::cvslam::test::underCi() ? ::testing::TestPartResult::kFatalFailure         \
                                       : ::testing::TestPartResult::kSkip,                \
             __FILE__, __LINE__,                                                          \
             ::cvslam::test::underCi() ? "CI=true: a facility this test needs is missing" \
                                       : "Skipped") = ::testing::Message()
