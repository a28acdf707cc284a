// Rotation part of a 3x3 deformation gradient, F = R S, for corotational elements.
#pragma once
#include <Eigen/Core>

namespace physics {

// Always a proper rotation (det R = +1, R^T R = I) and never NaN:
// - det F clearly positive: the polar factor by scaled Newton iteration (Higham), a few 3x3 inverses;
// - inverted or (nearly) flat elements: SVD F = U S V^T with the sign of the column of U belonging to
//   the smallest singular value flipped when det(U V^T) < 0, so the element is rotated towards its
//   closest uninverted shape instead of being reflected;
// - F with non-finite entries or F = 0: identity.
Eigen::Matrix3d rotation_from_deformation(const Eigen::Matrix3d &F);

} // namespace physics
