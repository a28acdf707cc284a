// The element loop over SIMD lanes: element_kernels.hpp's per-element functions run on batches of
// kElementLanes elements held as structure of arrays (gathered positions, rest shapes, rotations,
// outputs), one `omp simd` loop over the lanes per step, then the batch's blocks and forces are
// written out lane after lane in element order (lanes may share nodes and COO blocks).
#pragma once
#include "physics/corotational_assembly.hpp"

namespace physics {

// Elements per batch: 8 doubles fill an AVX-512 register, two AVX2 registers.
constexpr int kElementLanes = 8;

// assemble_elements' batched body (same contract; the checks are the caller's). Returns the number
// of elements whose rotation took the scalar path (inverted, flat or not converged in the fixed
// Newton steps).
long long assemble_elements_batched(const FemModel &model, const std::vector<int> &elements, const double *x,
                                    const double *v, const StepCoefficients &c, const BlockPattern *pattern,
                                    double *block_values, double *rhs, Eigen::Matrix3d *rotations);

// Estimated floating-point operations per element of the batched kernels (for -log_view's rates).
double element_kernel_flops(int order, bool with_blocks);

} // namespace physics
