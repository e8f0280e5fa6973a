#pragma once
// Eigen's dense decompositions on dynamic matrices, compiled once (dense.cc). Instantiating one
// costs seconds of compilation in every translation unit that does it, and five stages use the
// same few. Each function is the named Eigen decomposition on Eigen::MatrixXd, so its result is
// Eigen's own to the last bit.

#include <Eigen/Core>

namespace arcwheel::dense {

// Least squares of a x = b by column-pivoting Householder QR (rank-revealing); `rank`, when given,
// receives the decomposition's numerical rank (Eigen's default threshold).
[[nodiscard]] Eigen::VectorXd ColPivQrSolve(const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                                            Eigen::Index* rank = nullptr);
[[nodiscard]] Eigen::MatrixXd ColPivQrSolve(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

// The first a.cols() columns of Q of a's Householder QR: an orthonormal basis of a's columns,
// taken in order.
[[nodiscard]] Eigen::MatrixXd HouseholderThinQ(const Eigen::MatrixXd& a);

// x of a x = b for a symmetric a by LDLT (robust pivoting Cholesky).
[[nodiscard]] Eigen::VectorXd LdltSolve(const Eigen::MatrixXd& a, const Eigen::VectorXd& b);
[[nodiscard]] Eigen::MatrixXd LdltSolve(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

// The same for a 3 x 3 a: the normal equations of the circle fits, the association's Gauss-Newton
// step and the prediction's plane, solved by one instantiation.
[[nodiscard]] Eigen::Vector3d LdltSolve(const Eigen::Matrix3d& a, const Eigen::Vector3d& b);
[[nodiscard]] Eigen::Matrix3Xd LdltSolve(const Eigen::Matrix3d& a, const Eigen::Matrix3Xd& b);

// x of a x = b for a symmetric positive semi-definite a: LLT when a is positive definite, LDLT when
// the Cholesky factorisation fails.
[[nodiscard]] Eigen::VectorXd SemidefiniteSolve(const Eigen::MatrixXd& a, const Eigen::VectorXd& b);

// The singular value decomposition by two-sided Jacobi rotations (JacobiSVD): singular values
// largest first; u and v as `options` ask (Eigen::ComputeFullU, ComputeThinV, ...), else empty.
struct Svd {
  Eigen::VectorXd singular_values;
  Eigen::MatrixXd u;
  Eigen::MatrixXd v;
};
[[nodiscard]] Svd JacobiSvd(const Eigen::MatrixXd& a, unsigned int options = 0);

// The eigen-decomposition of a symmetric matrix: eigenvalues in increasing order, the unit
// eigenvectors as the columns of `vectors` in the same order.
struct SymmetricEigen {
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
};
[[nodiscard]] SymmetricEigen SymmetricEigenDecomposition(const Eigen::MatrixXd& a);

}  // namespace arcwheel::dense
