#include "cvslam/filter/measurement_batch.h"

#include <algorithm>

namespace cvslam {

void MeasurementBatch::reset(int state_size, int max_rows) {
  n_ = state_size;
  m_ = 0;
  if (H_.rows() < max_rows || H_.cols() != state_size) {
    H_.resize(std::max<Eigen::Index>(max_rows, H_.rows()), state_size);
  }
  if (r_.size() < max_rows) r_.resize(max_rows);
  if (R_.rows() < max_rows) R_.resize(max_rows, max_rows);
  H_.setZero();
  R_.setZero();
  groups_.clear();
  blocks_.clear();
}

int MeasurementBatch::addObservation(const Eigen::Ref<const Eigen::VectorXd>& residual,
                                     const Eigen::Ref<const Eigen::MatrixXd>& R) {
  const int rows = static_cast<int>(residual.size());
  if (m_ + rows > H_.rows() || R.rows() != rows || R.cols() != rows) return -1;
  r_.segment(m_, rows) = residual;
  R_.block(m_, m_, rows, rows) = R;
  groups_.push_back({m_, rows});
  m_ += rows;
  return static_cast<int>(groups_.size()) - 1;
}

void MeasurementBatch::setJacobian(int group, int col, const Eigen::Ref<const Eigen::MatrixXd>& J) {
  const Group& g = groups_[static_cast<std::size_t>(group)];
  const int cols = static_cast<int>(J.cols());
  H_.block(g.row, col, g.rows, cols) = J;
  for (const Block& b : blocks_) {
    if (b.row == g.row && b.col == col && b.cols == cols) return;  // overwritten in place
  }
  blocks_.push_back({g.row, g.rows, col, cols});
}

void MeasurementBatch::multiplyByHt(const Eigen::Ref<const Eigen::MatrixXd>& M,
                                    Eigen::MatrixXd* out) const {
  out->setZero(M.rows(), m_);
  for (const Block& b : blocks_) {
    // lazyProduct: the blocks are a few columns wide, where GEMM's blocking does not pay.
    out->middleCols(b.row, b.rows).noalias() +=
        M.middleCols(b.col, b.cols).lazyProduct(H_.block(b.row, b.col, b.rows, b.cols).transpose());
  }
}

void MeasurementBatch::multiplyH(const Eigen::Ref<const Eigen::MatrixXd>& M,
                                 Eigen::MatrixXd* out) const {
  out->setZero(m_, M.cols());
  for (const Block& b : blocks_) {
    out->middleRows(b.row, b.rows).noalias() +=
        H_.block(b.row, b.col, b.rows, b.cols).lazyProduct(M.middleRows(b.col, b.cols));
  }
}

}  // namespace cvslam
