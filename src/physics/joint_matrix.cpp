#include "physics/joint_matrix.hpp"

#include <algorithm>
#include <map>

namespace physics {

JointMatrixPattern build_joint_matrix_pattern(const ArticulatedScene &scene)
{
  JointMatrixPattern p;
  const int nb = static_cast<int>(scene.bodies.size());
  p.n_joints   = static_cast<int>(scene.joints.size());
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
  return p;
}

Eigen::Matrix3d body_coupling_block(double mass, const Eigen::Matrix3d &inverse_inertia_world, const Eigen::Vector3d &r1, const Eigen::Vector3d &r2)
{
  Eigen::Matrix3d c1, c2;
  c1 << 0, -r1.z(), r1.y(), r1.z(), 0, -r1.x(), -r1.y(), r1.x(), 0;
  c2 << 0, -r2.z(), r2.y(), r2.z(), 0, -r2.x(), -r2.y(), r2.x(), 0;
  return Eigen::Matrix3d::Identity() / mass - c1 * inverse_inertia_world * c2;
}

void fill_joint_matrix(const ArticulatedScene &scene, const JointMatrixPattern &pattern, double regularisation, std::vector<double> &block_values,
                       const std::vector<Eigen::Quaterniond> *orientations)
{
  block_values.assign(9 * pattern.block_row.size(), 0.0);
  std::vector<Eigen::Vector3d> arms;
  for (size_t g = 0; g + 1 < pattern.group_start.size(); ++g) {
    const int        body  = pattern.body_of_group[g];
    const RigidBody &b     = scene.bodies[body];
    const Eigen::Quaterniond q = orientations ? (*orientations)[body] : b.orientation;
    const Eigen::Matrix3d R = q.toRotationMatrix();
    const Eigen::Matrix3d inv_inertia = R * b.inertia_body.inverse() * R.transpose();
    const int        first = pattern.group_start[g], n = pattern.group_start[g + 1] - first;
    arms.resize(n);
    for (int p = 0; p < n; ++p) {
      const BallJoint &jt = scene.joints[pattern.group_joint[first + p]];
      arms[p]             = q * (pattern.group_sign[first + p] > 0 ? jt.anchor_a : jt.anchor_b);
    }
    for (int p = 0; p < n; ++p)
      for (int q = 0; q < n; ++q) {
        const Eigen::Matrix3d block = (pattern.group_sign[first + p] * pattern.group_sign[first + q]) * body_coupling_block(b.mass, inv_inertia, arms[p], arms[q]);
        double *out = &block_values[9 * pattern.pair_block[pattern.pair_start[g] + p * n + q]];
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) out[3 * r + c] += block(r, c);
      }
  }
  if (regularisation > 0)
    for (int j = 0; j < pattern.n_joints; ++j) {
      double *d     = &block_values[9 * pattern.diagonal_block[j]];
      const double shift = regularisation * (d[0] + d[4] + d[8]) / 3.0;
      d[0] += shift, d[4] += shift, d[8] += shift;
    }
}

void joint_matrix_multiply(const JointMatrixPattern &pattern, const std::vector<double> &block_values, const std::vector<double> &x, std::vector<double> &y)
{
  y.assign(3 * pattern.n_joints, 0.0);
  for (size_t k = 0; k < pattern.block_row.size(); ++k) {
    const double *a = &block_values[9 * k];
    const int     r = pattern.block_row[k], c = pattern.block_col[k];
    for (int i = 0; i < 3; ++i) y[3 * r + i] += a[3 * i] * x[3 * c] + a[3 * i + 1] * x[3 * c + 1] + a[3 * i + 2] * x[3 * c + 2];
  }
}

} // namespace physics
