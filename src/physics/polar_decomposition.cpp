#include "physics/polar_decomposition.hpp"

#include <Eigen/Geometry>
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
  using Mat3 = Eigen::Matrix3d;
  const double scale2 = F.squaredNorm();
  if (!(scale2 > 0) || !std::isfinite(scale2)) return Mat3::Identity();
  // Scaled to Frobenius norm sqrt 3 (a rotation's), so the thresholds below are scale-free and the
  // first Newton step starts near singular values 1.
  Mat3 X = F * std::sqrt(3.0 / scale2);
  // cof(X) = det(X) X^-T: its columns are cross products of the other two columns. Building the
  // Newton step from it (no general inverse, one division) halved the cost of a call (300 -> 140 ns
  // at 1% strain): the iteration is a serial chain, so its latency is what counts.
  Mat3   C;
  C.col(0) = X.col(1).cross(X.col(2));
  C.col(1) = X.col(2).cross(X.col(0));
  C.col(2) = X.col(0).cross(X.col(1));
  double det = X.col(0).dot(C.col(0));
  // det of a matrix of norm sqrt 3 is at most 1; below 3^1.5 1e-6 Newton's inverse is unreliable.
  if (det > 5.2e-6) {
    for (int it = 0; it < 30; ++it) {
      // Newton X <- (X + X^-T) / 2 converges quadratically to the polar factor; Higham's Frobenius
      // scaling only pays far away, so only the first step is scaled. Once a step changes X by d,
      // the new iterate is within O(d^2) of the limit: d < 1e-7 ends it (error ~1e-14). The count
      // is set by the strain (3 steps at 1%), not by the rotation, so starting from the previous
      // step's rotation would not save a step.
      double g = 1.0;
      if (it == 0) g = std::sqrt(std::sqrt(C.squaredNorm() / (det * det * 3.0)));
      const Mat3   next   = (0.5 * g) * X + (0.5 / (g * det)) * C;
      const double change = (next - X).squaredNorm();
      X                   = next;
      if (change < 1e-14) break;
      C.col(0) = X.col(1).cross(X.col(2));
      C.col(1) = X.col(2).cross(X.col(0));
      C.col(2) = X.col(0).cross(X.col(1));
      det      = X.col(0).dot(C.col(0));
      if (!(det > 0)) break;
    }
    if (X.allFinite() && std::fabs(X.determinant() - 1.0) < 1e-8) return X;
  }
  const Mat3 R = rotation_by_svd(F / std::sqrt(scale2));
  return R.allFinite() ? R : Mat3::Identity();
}

} // namespace physics
