#include "physics/joint_matrix.hpp"

#include <algorithm>
#include <map>

namespace physics {

JointMatrixPattern build_joint_matrix_pattern(const ArticulatedScene &scene)
{
  JointMatrixPattern p;
  const int          nb = static_cast<int>(scene.bodies.size());
  p.n_joints            = static_cast<int>(scene.joints.size());
  std::vector<std::vector<std::pair<int, int>>> joints_of_body(nb); // (joint, sign)
  for (int j = 0; j < p.n_joints; ++j) {
    const BallJoint &jt = scene.joints[j];
    if (jt.body_a != kWorld) joints_of_body[jt.body_a].push_back({j, +1});
    if (jt.body_b != kWorld) joints_of_body[jt.body_b].push_back({j, -1});
  }
  // Unique blocks; a pair of joints sharing two bodies gets one block with two contributions.
  std::map<std::pair<int, int>, int> index;
  for (int j = 0; j < p.n_joints; ++j) index[{j, j}] = 0;
  for (const auto &list : joints_of_body)
    for (const auto &a : list)
      for (const auto &b : list) index[{a.first, b.first}] = 0;
  int k = 0;
  for (auto &kv : index) {
    kv.second = k++;
    p.block_row.push_back(kv.first.first);
    p.block_col.push_back(kv.first.second);
  }
  p.diagonal_block.resize(p.n_joints);
  for (int j = 0; j < p.n_joints; ++j) p.diagonal_block[j] = index[{j, j}];
  p.group_start.push_back(0);
  p.pair_start.push_back(0);
  for (int b = 0; b < nb; ++b) {
    const auto &list = joints_of_body[b];
    if (list.empty()) continue;
    p.body_of_group.push_back(b);
    for (const auto &a : list) {
      p.group_joint.push_back(a.first);
      p.group_sign.push_back(a.second);
    }
    for (const auto &a : list)
      for (const auto &c : list) p.pair_block.push_back(index[{a.first, c.first}]);
    p.group_start.push_back(static_cast<int>(p.group_joint.size()));
    p.pair_start.push_back(static_cast<int>(p.pair_block.size()));
  }
  std::vector<char> reached(p.block_row.size(), 0);
  p.pair_first.resize(p.pair_block.size());
  for (size_t i = 0; i < p.pair_block.size(); ++i) {
    p.pair_first[i]          = !reached[p.pair_block[i]];
    reached[p.pair_block[i]] = 1;
  }
  for (size_t b = 0; b < reached.size(); ++b)
    if (!reached[b]) p.unreached_blocks.push_back(static_cast<int>(b));
  return p;
}

void fill_joint_matrix(const ArticulatedScene &scene, const JointMatrixPattern &pattern,
                       double regularisation, std::vector<double> &block_values,
                       const std::vector<Eigen::Quaterniond> *orientations)
{
  const size_t                 nb = scene.bodies.size(), nj = scene.joints.size();
  std::vector<Eigen::Matrix3d> inverse_inertia(nb);
  std::vector<Eigen::Vector3d> arm_a(nj), arm_b(nj);
  auto                         orientation = [&](int body) {
    return orientations ? (*orientations)[body] : scene.bodies[body].orientation;
  };
  for (size_t i = 0; i < nb; ++i) {
    const Eigen::Matrix3d R = orientation((int)i).toRotationMatrix();
    inverse_inertia[i]      = R * scene.bodies[i].inertia_body.inverse() * R.transpose();
  }
  for (size_t j = 0; j < nj; ++j) {
    const BallJoint &jt = scene.joints[j];
    arm_a[j] =
      jt.body_a == kWorld ? Eigen::Vector3d::Zero() : Eigen::Vector3d(orientation(jt.body_a) * jt.anchor_a);
    arm_b[j] =
      jt.body_b == kWorld ? Eigen::Vector3d::Zero() : Eigen::Vector3d(orientation(jt.body_b) * jt.anchor_b);
  }
  fill_joint_matrix(scene, pattern, regularisation, inverse_inertia, arm_a, arm_b, block_values);
}

void fill_joint_matrix(const ArticulatedScene &scene, const JointMatrixPattern &pattern,
                       double regularisation, const std::vector<Eigen::Matrix3d> &inverse_inertia_world,
                       const std::vector<Eigen::Vector3d> &arm_a, const std::vector<Eigen::Vector3d> &arm_b,
                       std::vector<double> &block_values, const std::vector<char> *group_mask)
{
  // Each block is written by the first pair that reaches it and added to by the others (pair_first), so
  // the values need no zeroing pass; a pattern without that map (built by hand) is zeroed first.
  const bool write_first = pattern.pair_first.size() == pattern.pair_block.size();
  if (!write_first || block_values.size() != 9 * pattern.block_row.size())
    block_values.assign(9 * pattern.block_row.size(), 0.0);
  for (int b : pattern.unreached_blocks) std::fill(&block_values[9 * b], &block_values[9 * b] + 9, 0.0);
  // Per joint end q of a body: I^-1 [r_q]x, so that block (p, q) = (1/m) I - [r_p]x (I^-1 [r_q]x) costs one
  // cross product per column. Most bodies carry 2 joints; the buffer is for the rare crowded one.
  constexpr int                kInline = 8;
  Eigen::Matrix3d              inline_buffer[kInline];
  std::vector<Eigen::Matrix3d> overflow;
  for (size_t g = 0; g + 1 < pattern.group_start.size(); ++g) {
    if (group_mask && !(*group_mask)[g]) continue;
    const int              body        = pattern.body_of_group[g];
    const double           inv_m       = 1.0 / scene.bodies[body].mass;
    const Eigen::Matrix3d &inv_inertia = inverse_inertia_world[body];
    const int              first = pattern.group_start[g], n = pattern.group_start[g + 1] - first;
    Eigen::Matrix3d       *turn = inline_buffer;
    if (n > kInline) overflow.resize(n), turn = overflow.data();
    for (int q = 0; q < n; ++q) {
      const int              j = pattern.group_joint[first + q];
      const Eigen::Vector3d &r = pattern.group_sign[first + q] > 0 ? arm_a[j] : arm_b[j];
      for (int c = 0; c < 3; ++c) turn[q].col(c) = inv_inertia * r.cross(Eigen::Vector3d::Unit(c));
    }
    for (int p = 0; p < n; ++p) {
      const int              jp = pattern.group_joint[first + p];
      const Eigen::Vector3d &rp = pattern.group_sign[first + p] > 0 ? arm_a[jp] : arm_b[jp];
      for (int q = 0; q < n; ++q) {
        const double sign  = pattern.group_sign[first + p] * pattern.group_sign[first + q];
        const int    pair  = pattern.pair_start[g] + p * n + q;
        double      *out   = &block_values[9 * pattern.pair_block[pair]];
        const bool   write = write_first && pattern.pair_first[pair];
        for (int c = 0; c < 3; ++c) {
          const Eigen::Vector3d col = -rp.cross(turn[q].col(c));
          for (int r = 0; r < 3; ++r) {
            const double v = sign * (col[r] + (r == c ? inv_m : 0.0));
            out[3 * r + c] =
              write ? v : out[3 * r + c] + v; // a select, not a product: stale NaNs do not survive
          }
        }
      }
    }
  }
  if (regularisation > 0)
    for (int j = 0; j < pattern.n_joints; ++j) {
      double      *d     = &block_values[9 * pattern.diagonal_block[j]];
      const double shift = regularisation * (d[0] + d[4] + d[8]) / 3.0;
      d[0] += shift, d[4] += shift, d[8] += shift;
    }
}

std::vector<char> joint_groups_of_rows(const JointMatrixPattern &pattern, const std::vector<int> &rows)
{
  std::vector<char> needed(pattern.n_joints, 0), mask(pattern.body_of_group.size(), 0);
  for (int r : rows) needed[r] = 1;
  for (size_t g = 0; g < mask.size(); ++g)
    for (int k = pattern.group_start[g]; k < pattern.group_start[g + 1] && !mask[g]; ++k)
      mask[g] = needed[pattern.group_joint[k]];
  return mask;
}

void joint_matrix_multiply(const JointMatrixPattern &pattern, const std::vector<double> &block_values,
                           const std::vector<double> &x, std::vector<double> &y)
{
  y.assign(3 * pattern.n_joints, 0.0);
  for (size_t k = 0; k < pattern.block_row.size(); ++k) {
    const double *a = &block_values[9 * k];
    const int     r = pattern.block_row[k], c = pattern.block_col[k];
    for (int i = 0; i < 3; ++i)
      y[3 * r + i] += a[3 * i] * x[3 * c] + a[3 * i + 1] * x[3 * c + 1] + a[3 * i + 2] * x[3 * c + 2];
  }
}

} // namespace physics
