#include "physics/polar_decomposition.hpp"
#include "physics/element_kernels.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace physics {

namespace {

// The Newton iteration's limits, shared by the scalar and the batched path (the batched one must stop
// where the scalar one does). For X scaled to Frobenius norm sqrt 3, det X is at most 1; below
// 3^1.5 1e-6 Newton's inverse is unreliable.
constexpr double kMinStartDet      = 5.2e-6;
constexpr int    kMaxNewtonSteps   = 30;
constexpr double kConvergedChange2 = 1e-14; // squared Frobenius change of a step: d < 1e-7
constexpr double kDetTolerance     = 1e-8;  // |det X - 1| accepted as a rotation

Eigen::Matrix3d rotation_by_svd(const Eigen::Matrix3d &F)
{
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d                   U = svd.matrixU();
  const Eigen::Matrix3d             V = svd.matrixV();
  // Singular values are sorted decreasingly: column 2 belongs to the smallest.
  if ((U * V.transpose()).determinant() < 0) U.col(2) *= -1.0;
  return U * V.transpose();
}

} // namespace

Eigen::Matrix3d rotation_from_deformation(const Eigen::Matrix3d &F)
{
  using Mat3          = Eigen::Matrix3d;
  const double scale2 = F.squaredNorm();
  if (!(scale2 > 0) || !std::isfinite(scale2)) return Mat3::Identity();
  // Scaled to Frobenius norm sqrt 3 (a rotation's), so the thresholds below are scale-free and the
  // first Newton step starts near singular values 1.
  Mat3 X = F * std::sqrt(3.0 / scale2);
  // cof(X) = det(X) X^-T: its columns are cross products of the other two columns. Building the
  // Newton step from it (no general inverse, one division) halved the cost of a call (300 -> 140 ns
  // at 1% strain): the iteration is a serial chain, so its latency is what counts.
  Mat3 C;
  C.col(0)   = X.col(1).cross(X.col(2));
  C.col(1)   = X.col(2).cross(X.col(0));
  C.col(2)   = X.col(0).cross(X.col(1));
  double det = X.col(0).dot(C.col(0));
  if (det > kMinStartDet) {
    for (int it = 0; it < kMaxNewtonSteps; ++it) {
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
      if (change < kConvergedChange2) break;
      C.col(0) = X.col(1).cross(X.col(2));
      C.col(1) = X.col(2).cross(X.col(0));
      C.col(2) = X.col(0).cross(X.col(1));
      det      = X.col(0).dot(C.col(0));
      if (!(det > 0)) break;
    }
    if (X.allFinite() && std::fabs(X.determinant() - 1.0) < kDetTolerance) return X;
  }
  const Mat3 R = rotation_by_svd(F / std::sqrt(scale2));
  return R.allFinite() ? R : Mat3::Identity();
}

void rotations_from_deformations(const Eigen::Matrix3d *F, Eigen::Matrix3d *R, std::size_t n)
{
  // The Newton iteration above, run on kLanes matrices side by side (structure of arrays, Eigen
  // packets across the lanes). One call is a serial chain of latencies (division, square roots,
  // reductions); lanes side by side overlap those chains. Each lane follows the scalar iteration step
  // for step; it stops where the scalar one would (its result is kept and the lane is set to the
  // identity, which stays put, until the other lanes are done). Lanes that start inverted or flat or
  // fail the final check take the scalar path, which ends in the SVD.
  constexpr int kLanes = 8;
  using Lanes          = Eigen::Array<double, kLanes, 1>;
  Lanes X[9], C[9], det;
  auto  cofactor     = [&] { kernels::cofactor3(X, C, det); }; // X column-major, X[0..2] its first column
  auto  set_identity = [&](int l) {
    for (int j = 0; j < 9; ++j) X[j][l] = j % 4 == 0 ? 1.0 : 0.0;
  };
  for (std::size_t start = 0; start < n; start += kLanes) {
    const int m      = static_cast<int>(std::min<std::size_t>(kLanes, n - start));
    Lanes     scale2 = Lanes::Zero();
    for (int l = 0; l < kLanes; ++l) { // lanes past the end hold the identity
      if (l < m)
        for (int j = 0; j < 9; ++j) X[j][l] = F[start + l].data()[j];
      else set_identity(l);
    }
    for (int j = 0; j < 9; ++j) scale2 += X[j].square();
    unsigned pending = 0, newton = 0; // lanes still iterating; lanes whose Newton result is in R
    for (int l = 0; l < kLanes; ++l) {
      if (l < m && scale2[l] > 0 && std::isfinite(scale2[l])) pending |= 1u << l;
      else scale2[l] = 3.0, set_identity(l);
    }
    // Scaled to Frobenius norm sqrt 3, as in the scalar path.
    const Lanes k = (3.0 / scale2).sqrt();
    for (int j = 0; j < 9; ++j) X[j] *= k;
    cofactor();
    for (int l = 0; l < kLanes; ++l)
      if ((pending >> l & 1) && !(det[l] > kMinStartDet)) pending &= ~(1u << l), set_identity(l);
    cofactor();
    // The first step with Higham's scaling g = (|cof X| / (sqrt 3 det))^(1/2), then plain steps.
    Lanes c2 = Lanes::Zero();
    for (int j = 0; j < 9; ++j) c2 += C[j].square();
    const Lanes g = (c2 / (det * det * 3.0)).sqrt().sqrt();
    Lanes       a = 0.5 * g, b = 0.5 / (g * det);
    for (int it = 0; it < kMaxNewtonSteps && pending; ++it) {
      Lanes change = Lanes::Zero();
      for (int j = 0; j < 9; ++j) {
        const Lanes next = a * X[j] + b * C[j];
        change += (next - X[j]).square();
        X[j] = next;
      }
      cofactor();
      // The scalar path stops once a step changed X by < 1e-7, or when det is no longer positive,
      // or after 30 steps, and then checks det(X) = 1 and X finite. The mask is built without
      // branches: which lanes stop in which step is unpredictable.
      unsigned stopping = 0;
      for (int l = 0; l < kLanes; ++l)
        stopping |= static_cast<unsigned>((change[l] < kConvergedChange2) | !(det[l] > 0)) << l;
      stopping = it == kMaxNewtonSteps - 1 ? pending : stopping & pending;
      pending &= ~stopping;
      for (; stopping; stopping &= stopping - 1) {
        const int l   = __builtin_ctz(stopping);
        double    sum = 0;
        for (int j = 0; j < 9; ++j) sum += (R[start + l].data()[j] = X[j][l]);
        if (std::isfinite(sum) && std::fabs(det[l] - 1.0) < kDetTolerance) newton |= 1u << l;
        set_identity(l);
      }
      a = 0.5;
      b = 0.5 / det;
    }
    for (int l = 0; l < m; ++l)
      if (!(newton >> l & 1)) R[start + l] = rotation_from_deformation(F[start + l]);
  }
}

} // namespace physics
