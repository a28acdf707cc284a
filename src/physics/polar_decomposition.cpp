#include "physics/polar_decomposition.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>

namespace physics {

namespace {

Eigen::Matrix3d rotation_by_svd(const Eigen::Matrix3d &F)
{
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  const Eigen::Matrix3d V = svd.matrixV();
  // Singular values are sorted decreasingly: column 2 belongs to the smallest.
  if ((U * V.transpose()).determinant() < 0) U.col(2) *= -1.0;
  return U * V.transpose();
}

} // namespace

Eigen::Matrix3d rotation_from_deformation(const Eigen::Matrix3d &F)
{
  if (!F.allFinite()) return Eigen::Matrix3d::Identity();
  const double scale = F.norm();
  if (!(scale > 0)) return Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d X0 = F / scale; // unit Frobenius norm: thresholds below are scale-free
  // det of a unit-norm matrix is at most 3^-1.5 ~ 0.19; below 1e-6 Newton's inverse is unreliable.
  if (X0.determinant() > 1e-6) {
    // Scaled Newton X <- (g X + X^-T / g) / 2 converges quadratically to the polar factor; once a
    // step changes X by d, the new iterate is within O(d^2) of the limit, so d < 1e-7 ends it
    // (error ~1e-14). Scaling only pays while far away; near convergence g = 1.
    Eigen::Matrix3d X = X0;
    bool            scaled = true;
    for (int it = 0; it < 30; ++it) {
      const Eigen::Matrix3d Xinv_t = X.inverse().transpose();
      const double gamma = scaled ? std::sqrt(std::sqrt(Xinv_t.squaredNorm() / X.squaredNorm())) : 1.0;
      const Eigen::Matrix3d next = 0.5 * (gamma * X + Xinv_t / gamma);
      const double change = (next - X).squaredNorm();
      X = next;
      if (change < 1e-14) break;
      scaled = change > 1e-4;
    }
    if (X.allFinite() && std::fabs(X.determinant() - 1.0) < 1e-8) return X;
  }
  const Eigen::Matrix3d R = rotation_by_svd(X0);
  return R.allFinite() ? R : Eigen::Matrix3d::Identity();
}

} // namespace physics
