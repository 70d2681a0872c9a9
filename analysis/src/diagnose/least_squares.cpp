#include "least_squares.hpp"

namespace rpem::analysis::least_squares {

TriangularFactor::TriangularFactor(Eigen::Index columns) : r_(0, columns), batch_(kBatch, columns) {}

void TriangularFactor::add_row(const double* row) {
  batch_.row(filled_++) = Eigen::Map<const Eigen::RowVectorXd>(row, batch_.cols());
  if (filled_ == kBatch) fold();
}

void TriangularFactor::add(TriangularFactor other) {
  other.fold();
  for (Eigen::Index i = 0; i < other.r_.rows(); ++i) {
    const Eigen::RowVectorXd row = other.r_.row(i);
    add_row(row.data());
  }
  fold();
}

void TriangularFactor::fold() {
  if (filled_ == 0) return;
  const Eigen::Index columns = batch_.cols();
  Eigen::MatrixXd stacked(r_.rows() + filled_, columns);
  stacked << r_, batch_.topRows(filled_);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(stacked);
  const Eigen::Index rows = std::min(stacked.rows(), columns);
  r_ = qr.matrixQR().topRows(rows).triangularView<Eigen::Upper>();
  filled_ = 0;
}

Eigen::MatrixXd TriangularFactor::r() {
  fold();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(batch_.cols(), batch_.cols());
  out.topRows(r_.rows()) = r_;
  return out;
}

Eigen::VectorXd gauss_newton_step(const Eigen::MatrixXd& jj, const Eigen::VectorXd& jr) {
  Eigen::MatrixXd h = jj;
  const double ridge = 1e-9 * std::max(h.trace(), 1e-300);
  h.diagonal().array() += ridge;
  return -h.ldlt().solve(jr);
}

double step_change(const Eigen::MatrixXd& jj, const Eigen::VectorXd& jr, const Eigen::VectorXd& delta) {
  return 2.0 * delta.dot(jr) + delta.dot(jj * delta);
}

}  // namespace rpem::analysis::least_squares
