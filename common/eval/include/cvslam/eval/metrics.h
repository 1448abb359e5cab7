#pragma once
// Evaluation metrics for estimator runs (consistency: NEES, co, Rco, thesis §5.7.3; the summary
// cvslam_eval writes is in docs/run_format.md; evaluation is a tool, not code inside the
// estimator).
//
// Our estimates and truths share the team's NED frame (thesis §6.3.1: initial poses known),
// so ATE compares positions directly by default. For real data whose ground truth lives in
// another world frame there are two alignments, as evo's `--align` and the rpg trajectory
// evaluation offer: SE(3) (Umeyama, no scale) and 4-DoF (yaw about the vertical +
// translation), the right one for a gravity-aligned visual-inertial estimate, whose roll and
// pitch are observable and must not be fitted away.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <utility>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/io/run_record.h"

namespace cvslam {

/// Pairs (i, j) of nearest samples with |a[i] − b[j]| ≤ tolerance; both inputs sorted.
/// Each sample is used at most once and the pairs are increasing in both indices.
std::vector<std::pair<std::size_t, std::size_t>> associateByTime(const std::vector<double>& a,
                                                                 const std::vector<double>& b,
                                                                 double tolerance);

enum class Alignment {
  kNone,  ///< shared frame (simulation, our NED convention)
  kSE3,   ///< rigid Umeyama alignment of the estimate onto the truth (real data)
  /// Rotation about the vertical + translation, both frames gravity-aligned. The vertical
  /// axis is ±z in each (NED: z down; EuRoC, ENU: z up); when the two point opposite ways,
  /// the estimate is first turned by π about x, and AteResult::vertical_flipped says so.
  kYaw,
};

/// Name of an alignment as the command line and the summary JSON spell it.
const char* alignmentName(Alignment a);

struct AteOptions {
  double time_tolerance_s = 0.01;  ///< max |t_est − t_true| for a pair [s]
  Alignment alignment = Alignment::kNone;
};

struct AteResult {
  double rmse_m = 0.0;
  double mean_m = 0.0;
  double max_m = 0.0;
  std::size_t pairs = 0;
  Eigen::Matrix3d R_align = Eigen::Matrix3d::Identity();  ///< applied to the estimate
  Eigen::Vector3d t_align = Eigen::Vector3d::Zero();
  /// kYaw: the estimate's vertical axis points opposite to the truth's (R_align includes
  /// the π turn about x).
  bool vertical_flipped = false;
};

/// Least-squares rotation about z and translation carrying the points `est` onto `tru`
/// (columns paired): the 4-DoF part of Umeyama's method, closed form. Needs ≥ 2 points.
Eigen::Isometry3d alignYawTranslation(const Eigen::Matrix3Xd& est, const Eigen::Matrix3Xd& tru);

/// Least-squares rigid transform carrying `est` onto `tru` (Umeyama, no scale; columns
/// paired). Needs ≥ 3 points.
Eigen::Isometry3d alignRigid(const Eigen::Matrix3Xd& est, const Eigen::Matrix3Xd& tru);

/// Absolute trajectory error of the positions. Fails with fewer than 1 pair (3 for SE(3),
/// 2 for yaw).
Expected<AteResult> absoluteTrajectoryError(const std::vector<TumPose>& estimate,
                                            const std::vector<TumPose>& truth,
                                            const AteOptions& options = {});

struct RpeOptions {
  double segment_m = 10.0;  ///< distance travelled (along the truth) per segment [m]
  double time_tolerance_s = 0.01;
};

struct RpeResult {
  double mean_m = 0.0;  ///< mean translation error of the relative pose per segment [m]
  double rmse_m = 0.0;
  std::size_t segments = 0;
};

/// Relative pose error per `segment_m` travelled: for every start pose, the pose reached
/// after segment_m along the true path; error = ‖trans((ΔT_true)⁻¹ ΔT_est)‖. Fails when the
/// trajectory is shorter than one segment.
Expected<RpeResult> relativePoseError(const std::vector<TumPose>& estimate,
                                      const std::vector<TumPose>& truth,
                                      const RpeOptions& options = {});

/// x_est − x_true with the Euler-angle differences wrapped to (−π, π].
Vector9d stateError(const Vector9d& x_est, const Vector9d& x_true);

struct NeesResult {
  double mean = 0.0;  ///< mean of eᵀ P⁻¹ e over the 9 vehicle states (≈ 9 if consistent)
  double mean_position = 0.0;   ///< the same over the position block (≈ 3)
  std::size_t steps = 0;        ///< steps used
  std::size_t skipped = 0;      ///< steps whose covariance was not positive definite
  std::vector<double> t, nees;  ///< per step
};

/// Normalised estimation error squared (thesis §5.7; Bar-Shalom). Uses P as recorded (full
/// or diagonal). `use_velocity` false leaves velocity out (truth without velocity).
Expected<NeesResult> normalisedEstimationErrorSquared(const std::vector<StateRecord>& estimate,
                                                      const std::vector<StateRecord>& truth,
                                                      double time_tolerance_s = 0.01,
                                                      bool use_velocity = true);

struct ConsistencyOptions {
  double time_tolerance_s = 0.01;
  /// The "true uncertainty" of a state is the RMS of its true error over the last `window`
  /// steps (1: the absolute error at that step, as in the thesis's figure 5.6).
  int window = 1;
  /// Steps whose true uncertainty is below this are skipped (co undefined) [state units].
  double min_true_sigma = 1e-9;
};

struct ConsistencyResult {
  std::array<double, 9> rco{};                  ///< Rco = min over time of co (thesis §5.7.3)
  std::array<double, 9> sigma_mean{};           ///< mean estimated σ
  std::array<double, 9> true_sigma_mean{};      ///< mean true uncertainty
  std::array<double, 9> fraction_consistent{};  ///< share of steps with co > 1
  std::vector<double> t;
  std::vector<Vector9d> co;  ///< co per step (NaN where undefined)
};

/// The thesis's consistency degree co = estimated σ / true uncertainty per state and step,
/// and Rco = min co over the run (§5.7.3: Rco ≤ 1 flags an inconsistent filter).
Expected<ConsistencyResult> consistencyDegree(const std::vector<StateRecord>& estimate,
                                              const std::vector<StateRecord>& truth,
                                              const ConsistencyOptions& options = {});

struct LandmarkErrorResult {
  std::size_t count = 0;                             ///< landmarks with a true position
  Eigen::Vector3d mean_m = Eigen::Vector3d::Zero();  ///< mean of (estimate − truth) per axis
  Eigen::Vector3d std_m = Eigen::Vector3d::Zero();   ///< standard deviation per axis
  double rms_m = 0.0;                                ///< RMS of the 3-D error
};

/// Landmark errors over the landmarks whose truth is known: the record's own truth, else
/// the landmark of the same id in `truth_landmarks`. Fails when none has a truth.
Expected<LandmarkErrorResult> landmarkErrors(
    const std::vector<LandmarkRecord>& landmarks,
    const std::vector<LandmarkRecord>& truth_landmarks = {});

/// Median (NaN for an empty input).
double median(std::vector<double> values);

}  // namespace cvslam
