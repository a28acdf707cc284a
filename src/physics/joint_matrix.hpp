// The joint system matrix A = J M^-1 J^T of ball joints: one 3x3 block row per joint, a nonzero block
// (j, k) wherever joints j and k share a body. The pattern (COO list of blocks, both triangles) is
// built once; the values are refilled in place every step from the bodies' current orientations.
#pragma once
#include "physics/articulated_scene.hpp"

#include <vector>

namespace physics {

struct JointMatrixPattern {
  int              n_joints = 0;
  std::vector<int> block_row, block_col; // COO of 3x3 blocks, row-sorted, no duplicates
  std::vector<int> diagonal_block;       // COO index of block (j, j)
  // For every body with joints: its joints, the sign of each (+1 if the body is end a), and the COO
  // index of each (joint p, joint q) pair, p-major. Flattened over bodies.
  std::vector<int> body_of_group, group_start; // group g covers joints group_start[g]..group_start[g+1]-1
  std::vector<int> group_joint, group_sign;
  std::vector<int> pair_start, pair_block; // pair_block[pair_start[g] + p*n_g + q]
  // 1 where a pair is the first (in group order) to reach its block: the fill writes there instead of
  // adding, so the 9 values per block need no zeroing pass first. Blocks that no body reaches are listed.
  std::vector<char> pair_first;
  std::vector<int>  unreached_blocks;
};

JointMatrixPattern build_joint_matrix_pattern(const ArticulatedScene &scene);

// Fills 9 values per COO block (row-major) for the scene's current orientations. Body i adds to block
// (p, q) of two of its joints s_p s_q ((1/m) I - [r_p]x I^-1 [r_q]x): the velocity change of the point at
// world arm r_p per unit impulse at arm r_q (s = +1 at end a, -1 at end b). regularisation > 0
// adds regularisation * (mean diagonal entry of the block) * I to each diagonal block.
// `orientations`, when given, replaces the bodies' orientations (the matrix at predicted positions).
void fill_joint_matrix(const ArticulatedScene &scene, const JointMatrixPattern &pattern,
                       double regularisation, std::vector<double> &block_values,
                       const std::vector<Eigen::Quaterniond> *orientations = nullptr);

// The same from what a time step has at hand already: every body's world inverse inertia and every joint's
// world arms (arm_a of end a, arm_b of end b; ignored for the world). Allocates nothing once block_values
// has its size. group_mask (one entry per body group of the pattern), when given, skips the bodies whose
// group is 0: the block rows of joints in marked groups are still complete (every body adding to block
// (p, q) carries joint p), the others are left unset (see joint_groups_of_rows).
void fill_joint_matrix(const ArticulatedScene &scene, const JointMatrixPattern &pattern,
                       double regularisation, const std::vector<Eigen::Matrix3d> &inverse_inertia_world,
                       const std::vector<Eigen::Vector3d> &arm_a, const std::vector<Eigen::Vector3d> &arm_b,
                       std::vector<double> &block_values, const std::vector<char> *group_mask = nullptr);

// The group mask that fills exactly the block rows `rows` (joints) completely: the bodies of those joints.
std::vector<char> joint_groups_of_rows(const JointMatrixPattern &pattern, const std::vector<int> &rows);

// y = A x with the block values (reference product for tests and diagnostics).
void joint_matrix_multiply(const JointMatrixPattern &pattern, const std::vector<double> &block_values,
                           const std::vector<double> &x, std::vector<double> &y);

} // namespace physics
