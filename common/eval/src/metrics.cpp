#include "cvslam/eval/metrics.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "cvslam/geometry/euler.h"

namespace cvslam {
namespace {

std::vector<double> times(const std::vector<TumPose>& poses) {
  std::vector<double> t;
  t.reserve(poses.size());
  for (const auto& p : poses) t.push_back(p.t);
  return t;
}

std::vector<double> times(const std::vector<StateRecord>& states) {
  std::vector<double> t;
  t.reserve(states.size());
  for (const auto& s : states) t.push_back(s.t);
  return t;
}

Eigen::Isometry3d isometry(const TumPose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = p.q_BtoN.normalized().toRotationMatrix();
  T.translation() = p.p_BinN;
  return T;
}

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> associateByTime(const std::vector<double>& a,
                                                                 const std::vector<double>& b,
                                                                 double tolerance) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  std::size_t j = 0;
  for (std::size_t i = 0; i < a.size() && j < b.size(); ++i) {
    // Advance j to the b sample nearest to a[i] (b is sorted).
    while (j + 1 < b.size() && std::abs(b[j + 1] - a[i]) <= std::abs(b[j] - a[i])) ++j;
    if (std::abs(b[j] - a[i]) <= tolerance) {
      pairs.emplace_back(i, j);
      ++j;  // each truth sample at most once
    }
  }
  return pairs;
}

const char* alignmentName(Alignment a) {
  switch (a) {
    case Alignment::kSE3:
      return "se3";
    case Alignment::kYaw:
      return "yaw";
    case Alignment::kNone:
      break;
  }
  return "none";
}

Eigen::Isometry3d alignYawTranslation(const Eigen::Matrix3Xd& est, const Eigen::Matrix3Xd& tru) {
  const Eigen::Vector3d mean_est = est.rowwise().mean();
  const Eigen::Vector3d mean_tru = tru.rowwise().mean();
  // Minimising Σ‖R_z(ψ)(e − ē) − (t − t̄)‖² over ψ: only the horizontal components depend on
  // ψ, and the optimum is ψ = atan2(Σ e × t |_z, Σ e · t |_xy) of the centred points.
  double s = 0.0, c = 0.0;
  for (Eigen::Index k = 0; k < est.cols(); ++k) {
    const Eigen::Vector3d e = est.col(k) - mean_est;
    const Eigen::Vector3d t = tru.col(k) - mean_tru;
    s += e.x() * t.y() - e.y() * t.x();
    c += e.x() * t.x() + e.y() * t.y();
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(std::atan2(s, c), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = mean_tru - T.linear() * mean_est;
  return T;
}

namespace {

double rmsDistance(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  return std::sqrt((a - b).colwise().squaredNorm().sum() / static_cast<double>(a.cols()));
}

/// kYaw: the better of the two vertical conventions (same or opposite ±z), reported.
void alignYaw(const Eigen::Matrix3Xd& est, const Eigen::Matrix3Xd& tru, AteResult* r) {
  const Eigen::Matrix3d flip = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();  // π about x
  const Eigen::Matrix3Xd est_flipped = flip * est;
  const Eigen::Isometry3d same = alignYawTranslation(est, tru);
  const Eigen::Isometry3d opposite = alignYawTranslation(est_flipped, tru);
  const double e_same = rmsDistance((same.linear() * est).colwise() + same.translation(), tru);
  const double e_opposite =
      rmsDistance((opposite.linear() * est_flipped).colwise() + opposite.translation(), tru);
  r->vertical_flipped = e_opposite < e_same;
  r->R_align = r->vertical_flipped ? Eigen::Matrix3d(opposite.linear() * flip) : same.linear();
  r->t_align = r->vertical_flipped ? opposite.translation() : same.translation();
}

}  // namespace

Eigen::Isometry3d alignRigid(const Eigen::Matrix3Xd& est, const Eigen::Matrix3Xd& tru) {
  return Eigen::Isometry3d(Eigen::Matrix4d(Eigen::umeyama(est, tru, false)));
}

Expected<AteResult> absoluteTrajectoryError(const std::vector<TumPose>& estimate,
                                            const std::vector<TumPose>& truth,
                                            const AteOptions& options) {
  const auto pairs = associateByTime(times(estimate), times(truth), options.time_tolerance_s);
  const std::size_t need = options.alignment == Alignment::kSE3   ? 3
                           : options.alignment == Alignment::kYaw ? 2
                                                                  : 1;
  if (pairs.size() < need)
    return Status::Error("ATE: only " + std::to_string(pairs.size()) +
                         " estimate/truth pairs within the time tolerance");
  Eigen::Matrix3Xd est(3, pairs.size()), tru(3, pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    est.col(static_cast<Eigen::Index>(k)) = estimate[pairs[k].first].p_BinN;
    tru.col(static_cast<Eigen::Index>(k)) = truth[pairs[k].second].p_BinN;
  }
  AteResult r;
  if (options.alignment == Alignment::kSE3) {
    const Eigen::Isometry3d T = alignRigid(est, tru);
    r.R_align = T.linear();
    r.t_align = T.translation();
  } else if (options.alignment == Alignment::kYaw) {
    alignYaw(est, tru, &r);
  }
  est = (r.R_align * est).colwise() + r.t_align;
  const Eigen::VectorXd err = (est - tru).colwise().norm();
  r.pairs = pairs.size();
  r.rmse_m = std::sqrt(err.squaredNorm() / static_cast<double>(err.size()));
  r.mean_m = err.mean();
  r.max_m = err.maxCoeff();
  return r;
}

Expected<RpeResult> relativePoseError(const std::vector<TumPose>& estimate,
                                      const std::vector<TumPose>& truth,
                                      const RpeOptions& options) {
  const auto pairs = associateByTime(times(estimate), times(truth), options.time_tolerance_s);
  if (pairs.size() < 2) return Status::Error("RPE: fewer than 2 estimate/truth pairs");
  std::vector<double> travelled(pairs.size(), 0.0);
  for (std::size_t k = 1; k < pairs.size(); ++k)
    travelled[k] = travelled[k - 1] +
                   (truth[pairs[k].second].p_BinN - truth[pairs[k - 1].second].p_BinN).norm();
  RpeResult r;
  double sum = 0.0, sum2 = 0.0;
  // Summed steps carry rounding: a segment of exactly segment_m must count as complete.
  const double segment = options.segment_m * (1.0 - 1e-9);
  std::size_t j = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    j = std::max(j, i);
    while (j < pairs.size() && travelled[j] - travelled[i] < segment) ++j;
    if (j >= pairs.size()) break;
    const Eigen::Isometry3d d_true =
        isometry(truth[pairs[i].second]).inverse() * isometry(truth[pairs[j].second]);
    const Eigen::Isometry3d d_est =
        isometry(estimate[pairs[i].first]).inverse() * isometry(estimate[pairs[j].first]);
    const double e = (d_true.inverse() * d_est).translation().norm();
    sum += e;
    sum2 += e * e;
    ++r.segments;
  }
  if (r.segments == 0)
    return Status::Error("RPE: the true path is shorter than one segment of " +
                         std::to_string(options.segment_m) + " m");
  r.mean_m = sum / static_cast<double>(r.segments);
  r.rmse_m = std::sqrt(sum2 / static_cast<double>(r.segments));
  return r;
}

Vector9d stateError(const Vector9d& x_est, const Vector9d& x_true) {
  Vector9d e = x_est - x_true;
  for (int i = 6; i < 9; ++i) e(i) = wrapAngle(e(i));
  return e;
}

Expected<NeesResult> normalisedEstimationErrorSquared(const std::vector<StateRecord>& estimate,
                                                      const std::vector<StateRecord>& truth,
                                                      double time_tolerance_s, bool use_velocity) {
  const auto pairs = associateByTime(times(estimate), times(truth), time_tolerance_s);
  if (pairs.empty()) return Status::Error("NEES: no estimate/truth pairs within the tolerance");
  // Indices of the states that enter the NEES.
  std::vector<int> idx = {0, 1, 2};
  if (use_velocity) idx.insert(idx.end(), {3, 4, 5});
  idx.insert(idx.end(), {6, 7, 8});
  const int n = static_cast<int>(idx.size());
  NeesResult r;
  double sum = 0.0, sum_pos = 0.0;
  for (const auto& [i, j] : pairs) {
    const Vector9d e9 = stateError(estimate[i].x, truth[j].x);
    Eigen::VectorXd e(n);
    Eigen::MatrixXd P(n, n);
    for (int a = 0; a < n; ++a) {
      e(a) = e9(idx[a]);
      for (int b = 0; b < n; ++b) P(a, b) = estimate[i].P(idx[a], idx[b]);
    }
    const Eigen::LLT<Eigen::MatrixXd> llt(P);
    const Eigen::LLT<Eigen::Matrix3d> llt_pos(estimate[i].P.topLeftCorner<3, 3>());
    if (llt.info() != Eigen::Success || llt_pos.info() != Eigen::Success) {
      ++r.skipped;
      continue;
    }
    const double nees = e.dot(llt.solve(e));
    const Eigen::Vector3d e_pos = e9.head<3>();
    sum += nees;
    sum_pos += e_pos.dot(llt_pos.solve(e_pos));
    r.t.push_back(estimate[i].t);
    r.nees.push_back(nees);
    ++r.steps;
  }
  if (r.steps == 0) return Status::Error("NEES: no step with a positive-definite covariance");
  r.mean = sum / static_cast<double>(r.steps);
  r.mean_position = sum_pos / static_cast<double>(r.steps);
  return r;
}

Expected<ConsistencyResult> consistencyDegree(const std::vector<StateRecord>& estimate,
                                              const std::vector<StateRecord>& truth,
                                              const ConsistencyOptions& options) {
  const auto pairs = associateByTime(times(estimate), times(truth), options.time_tolerance_s);
  if (pairs.empty()) return Status::Error("co: no estimate/truth pairs within the tolerance");
  const std::size_t window = static_cast<std::size_t>(std::max(1, options.window));
  ConsistencyResult r;
  r.rco.fill(std::numeric_limits<double>::infinity());
  std::array<int, 9> defined{}, consistent{};
  std::vector<Vector9d> sq_errors;
  for (const auto& [i, j] : pairs) {
    const Vector9d e = stateError(estimate[i].x, truth[j].x);
    sq_errors.push_back(e.cwiseAbs2());
    const std::size_t first = sq_errors.size() > window ? sq_errors.size() - window : 0;
    Vector9d mean_sq = Vector9d::Zero();
    for (std::size_t k = first; k < sq_errors.size(); ++k) mean_sq += sq_errors[k];
    const Vector9d true_sigma =
        (mean_sq / static_cast<double>(sq_errors.size() - first)).cwiseSqrt();
    Vector9d co;
    for (int s = 0; s < 9; ++s) {
      const double sigma = std::sqrt(std::max(0.0, estimate[i].P(s, s)));
      r.sigma_mean[s] += sigma;
      r.true_sigma_mean[s] += true_sigma(s);
      if (true_sigma(s) < options.min_true_sigma) {
        co(s) = std::numeric_limits<double>::quiet_NaN();
        continue;
      }
      co(s) = sigma / true_sigma(s);
      r.rco[s] = std::min(r.rco[s], co(s));
      ++defined[s];
      if (co(s) > 1.0) ++consistent[s];
    }
    r.t.push_back(estimate[i].t);
    r.co.push_back(co);
  }
  const double steps = static_cast<double>(pairs.size());
  for (int s = 0; s < 9; ++s) {
    r.sigma_mean[s] /= steps;
    r.true_sigma_mean[s] /= steps;
    r.fraction_consistent[s] = defined[s] ? static_cast<double>(consistent[s]) / defined[s] : 1.0;
  }
  return r;
}

Expected<LandmarkErrorResult> landmarkErrors(const std::vector<LandmarkRecord>& landmarks,
                                             const std::vector<LandmarkRecord>& truth_landmarks) {
  std::map<int64_t, Eigen::Vector3d> truth_by_id;
  for (const auto& l : truth_landmarks) truth_by_id[l.id] = l.truth ? *l.truth : l.p_LinN;
  std::vector<Eigen::Vector3d> errors;
  for (const auto& l : landmarks) {
    if (l.truth) {
      errors.push_back(l.p_LinN - *l.truth);
    } else if (auto it = truth_by_id.find(l.id); it != truth_by_id.end()) {
      errors.push_back(l.p_LinN - it->second);
    }
  }
  if (errors.empty()) return Status::Error("landmark errors: no landmark with a known truth");
  LandmarkErrorResult r;
  r.count = errors.size();
  for (const auto& e : errors) r.mean_m += e;
  r.mean_m /= static_cast<double>(r.count);
  double sq = 0.0;
  for (const auto& e : errors) {
    r.std_m += (e - r.mean_m).cwiseAbs2();
    sq += e.squaredNorm();
  }
  // Sample standard deviation (n − 1); zero for a single landmark.
  if (r.count > 1) {
    r.std_m = (r.std_m / static_cast<double>(r.count - 1)).cwiseSqrt().eval();
  } else {
    r.std_m.setZero();
  }
  r.rms_m = std::sqrt(sq / static_cast<double>(r.count));
  return r;
}

double median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  const double lower =
      *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid));
  return 0.5 * (lower + upper);
}

}  // namespace cvslam
