// The per-step element loop of the corotational FEM (the hot kernel), and the fixed sparsity pattern
// of 3x3 blocks that it fills.
//
// Per element e with nodes x_e (current), X_e (rest), v_e and rotation R (polar factor of the corner
// deformation gradient F = Ds Dm^-1; R = I for plain linear elasticity):
//   K_e  = R K0 R^T                       (rotated stiffness, symmetric positive semi-definite)
//   f_e  = -R K0 (R^T x_e - X_e)           (corotational elastic force; zero for any rigid motion)
//   rhs += a_f f_e - a_K K_e v_e - a_M M_e v_e
//   A_e  = c_M M_e + c_K K_e               (added into the element's blocks)
// The coefficients come from the time integrator (see implicit_euler_coefficients) or from a static
// solve (c_K = 1, a_f = 1).
#pragma once
#include "physics/element_batch.hpp"
#include "physics/fem_model.hpp"

#include <vector>

namespace physics {

struct StepCoefficients {
  double force            = 1; // a_f
  double stiffness_rhs    = 0; // a_K
  double mass_rhs         = 0; // a_M
  double mass_matrix      = 0; // c_M
  double stiffness_matrix = 0; // c_K
};

// Backward Euler, linearised once per step (Baraff & Witkin). With K = -df/dx symmetric positive
// (semi-)definite and Rayleigh damping D = alpha M + beta K, the implicit step
//   M (v1 - v0) = dt (f(x1) - D v1),   x1 = x0 + dt v1
// with f(x1) ~ f(x0) - K (x1 - x0) = f(x0) - dt K (v0 + dv), dv = v1 - v0, reads
//   M dv = dt f - dt^2 K v0 - dt^2 K dv - dt D v0 - dt D dv, i.e.
//   ((1 + dt alpha) M + (dt^2 + dt beta) K) dv = dt f - (dt^2 + dt beta) K v0 - dt alpha M v0.
// Without damping: (M + dt^2 K) dv = dt (f - dt K v0). The seed's "dt (f + dt K v)" is the same
// equation only with K = +df/dx (negative definite), where the matrix would read M - dt^2 K; with
// an SPD matrix the sign in front of dt K v must be minus (tests/unit/physics/fem checks the residual of
// backward Euler after one step).
StepCoefficients implicit_euler_coefficients(double dt, double rayleigh_alpha = 0, double rayleigh_beta = 0);

// COO list of 3x3 blocks for the elements one rank assembles, with fixed (Dirichlet) nodes
// eliminated: no block in a fixed node's row or column, and one identity block on the diagonal of
// every fixed node in [owned_begin, owned_end) (its right-hand side is 0, so its dv is 0 and the
// matrix stays SPD with a constant pattern).
struct BlockPattern {
  std::vector<int> rows, cols;     // global block indices, one entry per COO block
  std::vector<int> element_slots;  // per listed element npe*npe: COO block of (a,b), -1 if dropped
                                   // (fixed node, or a lower block the matrix does not store), with
                                   // kFirstContribution set on the kernels' first write to the block
  std::vector<int> identity_slots; // COO blocks that hold the identity (fixed nodes)
  bool             merged = false; // element blocks summed into unique COO blocks by the caller
  // The batched loop's write-out (element_batch.hpp's write groups): group g writes the COO blocks
  // write_slots[group_offsets[g] .. group_offsets[g+1]) (kFirstContribution set in the first group
  // that writes the block) in runs of equal term count: runs[2 r] terms per block for runs[2 r + 1]
  // blocks, r in [run_offsets[g], run_offsets[g+1]), the term counts growing, first writes before the
  // others and the blocks ascending within a run. The group's terms start at
  // write_terms[group_terms[g]], each block's in element order, each term
  // 2 (element in the group * upper blocks per element + packed pair) + 1 where its block goes in
  // transposed. (A count per run rather than an offset per block: the write-out reads 4 bytes less
  // per block written and loops a known number of times.)
  // element_nodes: the listed elements' nodes (npe each) in list order, which the batched loop reads
  // in order instead of through the element numbers (listed_element_nodes).
  struct WritePlan {
    std::vector<int>            group_offsets, write_slots, group_terms, run_offsets, runs;
    std::vector<unsigned short> write_terms;
    std::vector<int>            element_nodes;
  } plan;
};
// (kFirstContribution and kSlotIndexMask, the marks in element_slots: element_batch.hpp.)

// Blocks below the block diagonal (row > column) that the matrix does not store: sbaij keeps only the
// upper triangle; binbcsr with symmetric storage keeps the upper triangle of each rank's diagonal part
// and its off-rank part in full. Dropped blocks get no COO entry and the element loop skips them.
struct LowerTriangle {
  bool             drop = false; // leave out blocks with row > column ...
  std::vector<int> part_offsets; // ... except those whose row and column lie in different parts
                                 // [part_offsets[p], part_offsets[p+1]) (empty: no exception)
};
// merge_duplicates: rows/cols are unique, numbered in the order of the batched loop's first writes
// (the identity blocks last), and elements add into shared blocks; otherwise every element block has
// its own COO entry and the Mat type sums duplicates.
BlockPattern make_block_pattern(const FemModel &model, const std::vector<int> &elements,
                                const std::vector<char> &fixed, int owned_begin, int owned_end,
                                bool merge_duplicates, const LowerTriangle &lower = {});

// The nodes of `elements` (npe each, the mesh's order within an element) in list order.
std::vector<int> listed_element_nodes(const FemModel &model, const std::vector<int> &elements);

// Sizes block_values for the pattern and sets the identity blocks (fixed nodes), which the element
// loop does not write. Call before assemble_elements (once is enough while the array is kept).
void reset_block_values(const BlockPattern &pattern, std::vector<double> &block_values);
void reset_block_values(const BlockPattern &pattern, std::vector<float> &block_values);

// Which element loop runs: Batched (element_batch.hpp: the kernels of element_kernels.hpp over SIMD
// lanes, P2 from the barycentric gradients, in the body set `body` of assemble_elements) or Scalar
// (one element at a time, P2 from the stored K0: the reference the batched kernels are tested against).
enum class ElementKernel {
  Batched,
  Scalar
};

// The element loop. x, v: 3 per node (all nodes). rhs: 3 per node, accumulated (+=). block_values:
// 9 per COO block of `pattern`, row-major: every element block is overwritten with the sum of its
// element contributions (the identity blocks are left as they are); may be null (forces only;
// pattern may then be null too). rotations (optional): one per listed element. Returns the number of
// elements whose rotation took the scalar SVD path (inverted or flat; Batched also counts elements
// that the fixed Newton steps did not converge; Scalar returns 0). energy (optional): the state's
// energy and inverted elements over the listed elements, added (element_batch.hpp's ElementEnergy;
// Scalar computes it by element_energy, the definition).
long long assemble_elements(const FemModel &model, const std::vector<int> &elements, const double *x,
                            const double *v, const StepCoefficients &c, const BlockPattern *pattern,
                            double *block_values, double *rhs, Eigen::Matrix3d *rotations = nullptr,
                            ElementKernel    kernel = ElementKernel::Batched,
                            binbcsr::BodySet body = binbcsr::BodySet::Auto, ElementEnergy *energy = nullptr);

// The same with the blocks in single precision (for a matrix that stores single precision and takes
// float COO values, MatBinBCSRSetValuesCOOSingle): each block is summed in double and rounded to float
// where it is written; the batched loop writes half the bytes. (Scalar: through double blocks.)
long long assemble_elements_single(const FemModel &model, const std::vector<int> &elements, const double *x,
                                   const double *v, const StepCoefficients &c, const BlockPattern *pattern,
                                   float *block_values, double *rhs, Eigen::Matrix3d *rotations = nullptr,
                                   ElementKernel    kernel = ElementKernel::Batched,
                                   binbcsr::BodySet body   = binbcsr::BodySet::Auto,
                                   ElementEnergy   *energy = nullptr);

// Elastic forces only (a_f = 1): f = sum_e f_e over all elements, 3 per node, overwritten.
std::vector<double> elastic_forces(const FemModel &model, const double *x);

} // namespace physics
