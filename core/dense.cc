#include "core/dense.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

namespace arcwheel::dense {

Eigen::VectorXd ColPivQrSolve(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, Eigen::Index* rank) {
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  if (rank != nullptr) *rank = qr.rank();
  return qr.solve(b);
}

Eigen::MatrixXd ColPivQrSolve(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.colPivHouseholderQr().solve(b);
}

Eigen::MatrixXd HouseholderThinQ(const Eigen::MatrixXd& a) {
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(a);
  return qr.householderQ() * Eigen::MatrixXd::Identity(a.rows(), a.cols());
}

Eigen::VectorXd LdltSolve(const Eigen::MatrixXd& a, const Eigen::VectorXd& b) { return a.ldlt().solve(b); }

Eigen::MatrixXd LdltSolve(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return a.ldlt().solve(b); }

Eigen::Vector3d LdltSolve(const Eigen::Matrix3d& a, const Eigen::Vector3d& b) { return a.ldlt().solve(b); }

Eigen::Matrix3Xd LdltSolve(const Eigen::Matrix3d& a, const Eigen::Matrix3Xd& b) { return a.ldlt().solve(b); }

Eigen::VectorXd SemidefiniteSolve(const Eigen::MatrixXd& a, const Eigen::VectorXd& b) {
  const Eigen::LLT<Eigen::MatrixXd> llt(a);
  if (llt.info() == Eigen::Success) return llt.solve(b);
  return a.ldlt().solve(b);
}

Svd JacobiSvd(const Eigen::MatrixXd& a, unsigned int options) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, options);
  Svd result{svd.singularValues(), {}, {}};
  if (svd.computeU()) result.u = svd.matrixU();
  if (svd.computeV()) result.v = svd.matrixV();
  return result;
}

SymmetricEigen SymmetricEigenDecomposition(const Eigen::MatrixXd& a) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(a);
  return {eigen.eigenvalues(), eigen.eigenvectors()};
}

}  // namespace arcwheel::dense
