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

bool MeasurementBatch::touches(const Group& g, int col, int cols) const {
  for (const Block& b : blocks_) {
    if (b.row == g.row && b.col < col + cols && col < b.col + b.cols) return true;
  }
  return false;
}

void MeasurementBatch::cover(const Group& g, int col) {
  for (int c = col; c < col + 3; ++c) {
    if (!touches(g, c, 1)) blocks_.push_back({g.row, g.rows, c, 1});
  }
}

void MeasurementBatch::rotateColumns(int col, const Eigen::Matrix3d& R) {
  for (const Group& g : groups_) {
    if (touches(g, col, 3)) cover(g, col);
  }
  H_.topRows(m_).middleCols<3>(col) = (H_.topRows(m_).middleCols<3>(col) * R).eval();
}

void MeasurementBatch::addColumns(int dst, int src, const Eigen::Matrix3d& C) {
  for (const Group& g : groups_) {
    if (touches(g, src, 3)) cover(g, dst);
  }
  H_.topRows(m_).middleCols<3>(dst).noalias() += H_.topRows(m_).middleCols<3>(src) * C;
}

}  // namespace cvslam
