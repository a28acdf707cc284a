#include "physics/fem_model.hpp"
#include "physics/polar_decomposition.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace physics {

namespace {

Eigen::Matrix<double, 3, 4> corner_matrix(const TetMesh &mesh, const double *pos, int e)
{
  Eigen::Matrix<double, 3, 4> X;
  const int                  *n = &mesh.elements[static_cast<size_t>(e) * mesh.nodes_per_element()];
  for (int k = 0; k < 4; ++k)
    for (int d = 0; d < 3; ++d) X(d, k) = pos[3 * n[k] + d];
  return X;
}

} // namespace

FemModel make_fem_model(const TetMesh &mesh, const FemSettings &settings)
{
  validate_mesh(mesh, "mesh");
  const LameParameters lame = lame_from_young_poisson(settings.young, settings.poisson);
  if (!(settings.density > 0) || !std::isfinite(settings.density))
    throw std::invalid_argument("material: density must be > 0 and finite");
  FemModel m;
  m.mesh       = mesh;
  m.settings   = settings;
  m.npe        = mesh.nodes_per_element();
  m.lame       = lame;
  const int ne = mesh.element_count();
  m.rest_shape_inverse.resize(ne);
  m.volume.resize(ne);
  for (int e = 0; e < ne; ++e) {
    const TetGeometry g = tet_geometry(corner_matrix(mesh, mesh.nodes.data(), e));
    if (mesh.order == 2) {
      // K0 and M assume the affine (straight-sided) map of the corners: refuse curved elements.
      const int *n = &mesh.elements[static_cast<size_t>(e) * 10];
      for (int k = 0; k < 6; ++k) {
        const int a = n[kTetEdges[k][0]], b = n[kTetEdges[k][1]], mid = n[4 + k];
        double    dev = 0, len = 0;
        for (int d = 0; d < 3; ++d) {
          dev += std::pow(mesh.nodes[3 * mid + d] - 0.5 * (mesh.nodes[3 * a + d] + mesh.nodes[3 * b + d]), 2);
          len += std::pow(mesh.nodes[3 * a + d] - mesh.nodes[3 * b + d], 2);
        }
        if (dev > 1e-12 * len)
          throw std::runtime_error(
            "mesh: element " + std::to_string(e) +
            " is a curved 10-node tetrahedron (edge node off its edge's midpoint); only straight-sided "
            "elements are supported: mesh with order 1 and use -fem_order 2, or set "
            "Mesh.SecondOrderLinear = 1 in gmsh");
      }
    }
    m.rest_shape_inverse[e] = g.rest_shape_inverse;
    m.volume[e]             = g.volume;
    if (mesh.order == 1)
      for (int a = 0; a < 4; ++a)
        for (int d = 0; d < 3; ++d) m.gradients.push_back(g.grad_barycentric(a, d));
  }
  m.reference_mass = reference_mass(mesh.order, settings.mass);
  m.diagonal_mass  = m.reference_mass.isDiagonal();
  return m;
}

const double *element_stiffness_blocks(const FemModel &model, int e)
{
  const int    ne = model.element_count(), nb = packed_block_count(model.npe);
  const size_t per_element = static_cast<size_t>(nb) * 9;
  if (model.stiffness.size() != static_cast<size_t>(ne) * per_element) {
    model.stiffness.assign(static_cast<size_t>(ne) * per_element, 0.0);
    for (int k = 0; k < ne; ++k) {
      const TetGeometry     g   = tet_geometry(corner_matrix(model.mesh, model.mesh.nodes.data(), k));
      const Eigen::MatrixXd K   = element_stiffness(g, model.mesh.order, model.lame);
      double               *out = &model.stiffness[k * per_element];
      for (int a = 0; a < model.npe; ++a)
        for (int b = a; b < model.npe; ++b)
          Eigen::Map<Eigen::Matrix3d>(out + 9 * packed_block(a, b, model.npe)) = K.block<3, 3>(3 * a, 3 * b);
    }
  }
  return &model.stiffness[static_cast<size_t>(e) * per_element];
}

std::vector<double> gravity_forces(const FemModel &model, const std::array<double, 3> &g)
{
  std::vector<double>   f(3 * static_cast<size_t>(model.node_count()), 0.0);
  const Eigen::VectorXd row_sums = model.reference_mass.rowwise().sum();
  for (int e = 0; e < model.element_count(); ++e) {
    const int   *n = &model.mesh.elements[static_cast<size_t>(e) * model.npe];
    const double m = model.settings.density * model.volume[e];
    for (int a = 0; a < model.npe; ++a)
      for (int d = 0; d < 3; ++d) f[3 * n[a] + d] += m * row_sums[a] * g[d];
  }
  return f;
}

std::array<double, 3> linear_momentum(const FemModel &model, const double *v)
{
  std::array<double, 3> p{0, 0, 0};
  const Eigen::VectorXd col_sums = model.reference_mass.colwise().sum();
  for (int e = 0; e < model.element_count(); ++e) {
    const int   *n = &model.mesh.elements[static_cast<size_t>(e) * model.npe];
    const double m = model.settings.density * model.volume[e];
    for (int b = 0; b < model.npe; ++b)
      for (int d = 0; d < 3; ++d) p[d] += m * col_sums[b] * v[3 * n[b] + d];
  }
  return p;
}

double total_mass(const FemModel &model)
{
  double s = 0;
  for (double v : model.volume) s += v;
  return s * model.settings.density * model.reference_mass.sum();
}

FemEnergy element_energy(const FemModel &model, const double *x, const double *v, int e)
{
  FemEnergy                    E;
  const int                    npe = model.npe;
  const auto                  &X   = model.mesh.nodes;
  Eigen::Matrix<double, 30, 1> u, Ku; // up to 10 nodes
  const int                   *n = &model.mesh.elements[static_cast<size_t>(e) * npe];
  Eigen::Matrix3d              R = Eigen::Matrix3d::Identity();
  if (model.settings.corotational) {
    Eigen::Matrix3d Ds;
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) Ds(d, k) = x[3 * n[k + 1] + d] - x[3 * n[0] + d];
    R = rotation_from_deformation(Ds * model.rest_shape_inverse[e]);
  }
  for (int a = 0; a < npe; ++a)
    u.segment<3>(3 * a) = R.transpose() * Eigen::Vector3d(x[3 * n[a]], x[3 * n[a] + 1], x[3 * n[a] + 2]) -
                          Eigen::Vector3d(X[3 * n[a]], X[3 * n[a] + 1], X[3 * n[a] + 2]);
  const double *K = element_stiffness_blocks(model, e);
  Ku.setZero();
  for (int a = 0; a < npe; ++a)
    for (int b = a; b < npe; ++b) {
      const Eigen::Map<const Eigen::Matrix3d> Kab(K + 9 * packed_block(a, b, npe));
      Ku.segment<3>(3 * a) += Kab * u.segment<3>(3 * b);
      if (b != a) Ku.segment<3>(3 * b) += Kab.transpose() * u.segment<3>(3 * a);
    }
  E.elastic      = 0.5 * u.head(3 * npe).dot(Ku.head(3 * npe));
  const double m = model.settings.density * model.volume[e];
  for (int a = 0; a < npe; ++a)
    for (int b = 0; b < npe; ++b) {
      const double mab = m * model.reference_mass(a, b);
      if (mab == 0) continue;
      for (int d = 0; d < 3; ++d) E.kinetic += 0.5 * mab * v[3 * n[a] + d] * v[3 * n[b] + d];
    }
  return E;
}

FemEnergy fem_energy(const FemModel &model, const double *x, const double *v)
{
  FemEnergy E;
  for (int e = 0; e < model.element_count(); ++e) {
    const FemEnergy t = element_energy(model, x, v, e);
    E.elastic += t.elastic;
    E.kinetic += t.kinetic;
  }
  return E;
}

} // namespace physics
