#pragma once
// A stacked measurement (H, r, R) for one filter update, stored block-sparse.
//
// A stereo observation touches the vehicle and one landmark only, so H is mostly zeros once
// ~20 observations are stacked over a state of ~80. The batch keeps H dense (storage reused
// between updates, no allocation per observation) but remembers which blocks were set, and
// its products P Hᵀ and H M skip the zero blocks: O(n · nnz(H)) instead of O(n² m).
//
// Observations are groups of rows with their own noise block; R is block diagonal across
// groups (independent observations). Gating is per group (CovarianceHelper::update).

#include <Eigen/Core>
#include <vector>

#include "cvslam/filter/slam_state.h"

namespace cvslam {

class MeasurementBatch {
 public:
  /// Empties the batch for a state of `state_size`, with room for `max_rows` rows. Storage
  /// only grows, so a batch reused every frame stops allocating.
  void reset(int state_size, int max_rows);

  /// Appends an observation (its residual z − h(x) and noise covariance); returns its group
  /// index. Returns −1 when the rows do not fit in max_rows.
  int addObservation(const Eigen::Ref<const Eigen::VectorXd>& residual,
                     const Eigen::Ref<const Eigen::MatrixXd>& R);

  /// Sets ∂h/∂x of `group` w.r.t. state columns [col, col + J.cols()). Setting the same block
  /// again overwrites it.
  void setJacobian(int group, int col, const Eigen::Ref<const Eigen::MatrixXd>& J);
  void setJacobian(int group, const StateVariable& v, const Eigen::Ref<const Eigen::MatrixXd>& J) {
    setJacobian(group, v.index, J);
  }

  /// H(:, [col, col + 3)) ← H(:, [col, col + 3)) R (a change of error coordinates,
  /// invariant_chart_transport.h); the block sparsity follows.
  void rotateColumns(int col, const Eigen::Matrix3d& R);
  /// H(:, [dst, dst + 3)) += H(:, [src, src + 3)) C; the block sparsity follows.
  void addColumns(int dst, int src, const Eigen::Matrix3d& C);
  /// r ← r + d over the used rows (an iterated update's H (x_i ⊟ x_prior) term).
  void shiftResidual(const Eigen::Ref<const Eigen::VectorXd>& d) { r_.head(m_) += d; }
  int stateSize() const { return n_; }
  int rows() const { return m_; }
  int groups() const { return static_cast<int>(groups_.size()); }
  int groupRow(int g) const { return groups_[static_cast<std::size_t>(g)].row; }
  int groupRows(int g) const { return groups_[static_cast<std::size_t>(g)].rows; }

  /// Views of the used rows.
  Eigen::Block<const Eigen::MatrixXd> H() const { return H_.topRows(m_); }
  Eigen::VectorBlock<const Eigen::VectorXd> residual() const { return r_.head(m_); }
  Eigen::Block<const Eigen::MatrixXd> R() const { return R_.topLeftCorner(m_, m_); }

  /// out = M Hᵀ for any M with n columns (out: M.rows() × m). Sparse in H.
  void multiplyByHt(const Eigen::Ref<const Eigen::MatrixXd>& M, Eigen::MatrixXd* out) const;
  /// out = H M for any M with n rows (out: m × M.cols()). Sparse in H.
  void multiplyH(const Eigen::Ref<const Eigen::MatrixXd>& M, Eigen::MatrixXd* out) const;

 private:
  struct Group {
    int row = 0;
    int rows = 0;
  };
  struct Block {
    int row = 0, rows = 0, col = 0, cols = 0;
  };
  int n_ = 0;
  int m_ = 0;
  Eigen::MatrixXd H_;
  Eigen::VectorXd r_;
  Eigen::MatrixXd R_;
  /// Whether a block of the rows of `g` touches a column of [col, col + cols).
  bool touches(const Group& g, int col, int cols) const;
  /// Adds one-column blocks so that the rows of `g` cover every column of [col, col + 3).
  void cover(const Group& g, int col);
  std::vector<Group> groups_;
  std::vector<Block> blocks_;
};

}  // namespace cvslam
