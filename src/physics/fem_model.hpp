// A deformable body discretised with linear or quadratic tetrahedra: the rest-state data every step
// reuses (element stiffness K0, mass, rest shape), built once from a mesh and a material.
#pragma once
#include "physics/tet_element.hpp"
#include "physics/tet_mesh.hpp"

#include <Eigen/Core>
#include <array>
#include <vector>

namespace physics {

struct FemSettings {
  double      young        = 1e6; // Pa
  double      poisson      = 0.3;
  double      density      = 1000;                    // kg/m^3
  bool        corotational = true;                    // false: plain linear elasticity (R = I)
  MassLumping mass         = MassLumping::Consistent; // order 2 only; order 1 is always lumped
};

// Index of block (a, b), a <= b, among the upper blocks of an n x n block matrix stored row by row.
constexpr int packed_block(int a, int b, int n) { return a * n - a * (a - 1) / 2 + (b - a); }
constexpr int packed_block_count(int n) { return n * (n + 1) / 2; }

struct FemModel {
  TetMesh                      mesh;
  FemSettings                  settings;
  int                          npe = 4;            // nodes per element
  std::vector<Eigen::Matrix3d> rest_shape_inverse; // per element: Dm^-1 of the corner tetrahedron
  std::vector<double>          volume;             // per element
  // Per element the npe (npe+1) / 2 upper 3x3 blocks of K0 (block (a,b), a <= b, at
  // 9 * packed_block(a, b, npe) of the element's range; column-major like Eigen). K0_ba = K0_ab^T.
  // Built at its first use (element_stiffness_blocks): the batched element loop never reads it, and
  // made with the model it was most of the model's set-up (linear_38k: 43 MB written at start).
  mutable std::vector<double> stiffness;
  // Order 1 only: per element the 4 gradients of the barycentric coordinates (12 values, node-major),
  // so the kernel forms R K0 R^T from rotated gradients instead of reading K0.
  std::vector<double> gradients;
  LameParameters      lame{0, 0};
  Eigen::MatrixXd     reference_mass; // npe x npe, per unit density and volume
  bool                diagonal_mass = true;

  int node_count() const { return mesh.node_count(); }
  int element_count() const { return mesh.element_count(); }
};

// Validates the mesh (throws std::runtime_error) and the material (std::invalid_argument).
FemModel make_fem_model(const TetMesh &mesh, const FemSettings &settings);

// Element e's K0 blocks (FemModel::stiffness), every element's built at the first call (which writes
// the model: not to be raced by two threads on one model).
const double *element_stiffness_blocks(const FemModel &model, int e);

// M g per node (3 per node): the consistent load of gravity g for the model's mass matrix.
std::vector<double> gravity_forces(const FemModel &model, const std::array<double, 3> &g);

// sum of M v: linear momentum (3 components).
std::array<double, 3> linear_momentum(const FemModel &model, const double *v);

double total_mass(const FemModel &model);

struct FemEnergy {
  double kinetic = 0; // v^T M v / 2
  double elastic = 0; // sum over elements u^T K0 u / 2, u = R^T x - X (R = I when not corotational)
};
FemEnergy fem_energy(const FemModel &model, const double *x, const double *v);
// Element e's terms of fem_energy (the definition the element loop's ElementEnergy is tested against).
FemEnergy element_energy(const FemModel &model, const double *x, const double *v, int e);

} // namespace physics
