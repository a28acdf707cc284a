// Element-level physics: polar decomposition, shape-function integrals, rigid-rotation invariance of
// corotational forces, patch tests for P1 and P2.
#include <catch2/catch.hpp>

#include "fem_test_util.hpp"
#include "physics/box_mesh.hpp"
#include "physics/polar_decomposition.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>

using namespace physics;

namespace {

bool is_rotation(const Eigen::Matrix3d &R, double tol = 1e-10)
{
  return R.allFinite() && (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < tol &&
         std::fabs(R.determinant() - 1) < tol;
}

Eigen::Matrix3d some_rotation()
{
  return Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -0.8, 0.5).normalized()).toRotationMatrix();
}

// Irregular mesh: box with its interior nodes jittered.
// A uniformly random rotation (normalised Gaussian quaternion), drawn with the caller's generator.
Eigen::Matrix3d random_rotation(std::mt19937 &rng, std::normal_distribution<double> &normal)
{
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

TetMesh jittered_box(int order)
{
  TetMesh                                m = make_box_mesh(1.0, 0.8, 0.6, 3, 3, 3);
  std::mt19937                           rng(7);
  std::uniform_real_distribution<double> u(-0.06, 0.06);
  for (int i = 0; i < m.node_count(); ++i) {
    bool         interior = true;
    const double ext[3]   = {1.0, 0.8, 0.6};
    for (int d = 0; d < 3; ++d)
      interior = interior && m.nodes[3 * i + d] > 1e-9 && m.nodes[3 * i + d] < ext[d] - 1e-9;
    if (interior)
      for (int d = 0; d < 3; ++d) m.nodes[3 * i + d] += u(rng);
  }
  return order == 2 ? promote_to_quadratic(m) : m;
}

} // namespace

TEST_CASE("polar decomposition: proper rotation for regular, inverted, flat and broken F", "[fem][polar]")
{
  const Eigen::Matrix3d Q = some_rotation();
  Eigen::Matrix3d       S;
  S << 1.3, 0.2, -0.1, 0.2, 0.8, 0.05, -0.1, 0.05, 1.1; // SPD stretch
  const Eigen::Matrix3d R = rotation_from_deformation(Q * S);
  CHECK(is_rotation(R));
  CHECK((R - Q).norm() < 1e-10);

  // Inverted: reflect one axis. Must stay a proper rotation, and R^T F symmetric.
  const Eigen::Matrix3d F_inv = Q * Eigen::DiagonalMatrix<double, 3>(1.0, 1.0, -0.2) * S;
  const Eigen::Matrix3d R_inv = rotation_from_deformation(F_inv);
  CHECK(is_rotation(R_inv));
  const Eigen::Matrix3d Sym = R_inv.transpose() * F_inv;
  CHECK((Sym - Sym.transpose()).norm() < 1e-9);

  // Flat (rank 2), collapsed (rank 1), zero, non-finite.
  Eigen::Matrix3d flat = Q * Eigen::DiagonalMatrix<double, 3>(1.0, 2.0, 0.0);
  CHECK(is_rotation(rotation_from_deformation(flat)));
  CHECK((rotation_from_deformation(flat) - Q).norm() < 1e-9);
  CHECK(is_rotation(rotation_from_deformation(Q * Eigen::DiagonalMatrix<double, 3>(1.0, 0.0, 0.0))));
  CHECK(is_rotation(rotation_from_deformation(Eigen::Matrix3d::Zero())));
  Eigen::Matrix3d nan = Eigen::Matrix3d::Identity();
  nan(1, 2)           = std::nan("");
  CHECK(is_rotation(rotation_from_deformation(nan)));
  // Tiny but regular elements (scale-free thresholds).
  CHECK((rotation_from_deformation(1e-9 * Q * S) - Q).norm() < 1e-9);
}

TEST_CASE("polar decomposition agrees with the SVD polar factor on random F, near inversion too",
          "[fem][polar]")
{
  std::mt19937                           rng(11);
  std::normal_distribution<double>       normal(0, 1);
  std::uniform_real_distribution<double> uniform(0, 1);
  double                                 worst = 0;
  for (int k = 0; k < 2000; ++k) {
    // F = U diag(s) V^T with singular values between 0.05 and 3 (strains of 1e-6 to 200%).
    const double    spread = std::pow(10.0, -6 + 6 * uniform(rng));
    Eigen::Vector3d s;
    for (int d = 0; d < 3; ++d) s[d] = std::max(0.05, 1 + spread * normal(rng));
    const Eigen::Matrix3d U = random_rotation(rng, normal), V = random_rotation(rng, normal);
    const Eigen::Matrix3d F = U * s.asDiagonal() * V.transpose();
    const Eigen::Matrix3d R = rotation_from_deformation(F);
    REQUIRE(is_rotation(R));
    worst = std::max(worst, (R - U * V.transpose()).norm());
  }
  CHECK(worst < 1e-12);
  // Across inversion: smallest singular value from +1e-3 through 0 to -1e-3 (one axis reflected).
  // The rotation is the one of the sign-corrected SVD, a proper rotation, and continuous.
  const Eigen::Matrix3d U = random_rotation(rng, normal), V = random_rotation(rng, normal);
  Eigen::Matrix3d       previous = Eigen::Matrix3d::Zero();
  for (int k = -10; k <= 10; ++k) {
    const Eigen::Matrix3d F = U * Eigen::Vector3d(1.2, 0.9, 1e-4 * k).asDiagonal() * V.transpose();
    const Eigen::Matrix3d R = rotation_from_deformation(F);
    CHECK(is_rotation(R));
    CHECK((R - U * V.transpose()).norm() < 1e-9);
    if (k > -10) CHECK((R - previous).norm() < 1e-9);
    previous = R;
  }
}

TEST_CASE("batched polar decomposition: the scalar path's rotations, special lanes mixed into batches",
          "[fem][polar]")
{
  std::mt19937                           rng(5);
  std::normal_distribution<double>       normal(0, 1);
  std::uniform_real_distribution<double> uniform(0, 1);
  std::vector<Eigen::Matrix3d>           F, polar; // polar: U V^T where known (zero: no reference)
  for (int k = 0; k < 2000; ++k) {
    const double    spread = std::pow(10.0, -6 + 6 * uniform(rng));
    Eigen::Vector3d s;
    for (int d = 0; d < 3; ++d) s[d] = std::max(0.05, 1 + spread * normal(rng));
    const Eigen::Matrix3d U = random_rotation(rng, normal), V = random_rotation(rng, normal);
    F.push_back(std::pow(10.0, -3 + 6 * uniform(rng)) * U * s.asDiagonal() * V.transpose());
    polar.push_back(U * V.transpose());
  }
  // Through inversion (the smallest singular value from +1e-3 to -1e-3): sign-corrected SVD.
  const Eigen::Matrix3d U = random_rotation(rng, normal), V = random_rotation(rng, normal);
  for (int k = -10; k <= 10; ++k) {
    F.push_back(U * Eigen::Vector3d(1.2, 0.9, 1e-4 * k).asDiagonal() * V.transpose());
    polar.push_back(U * V.transpose());
  }
  // Strongly inverted, flat, collapsed, zero, non-finite: compared with the scalar path only.
  const Eigen::Matrix3d Q   = some_rotation();
  Eigen::Matrix3d       nan = Eigen::Matrix3d::Identity(), inf = Eigen::Matrix3d::Identity();
  nan(1, 2) = std::nan("");
  inf(0, 1) = std::numeric_limits<double>::infinity();
  for (const Eigen::Matrix3d &special :
       {Eigen::Matrix3d(-Q), Eigen::Matrix3d(Q * Eigen::DiagonalMatrix<double, 3>(1.0, 1.0, -0.2)),
        Eigen::Matrix3d(Q * Eigen::DiagonalMatrix<double, 3>(1.0, 2.0, 0.0)),
        Eigen::Matrix3d(Q * Eigen::DiagonalMatrix<double, 3>(1.0, 0.0, 0.0)),
        Eigen::Matrix3d(Eigen::Matrix3d::Zero()), nan, inf}) {
    F.push_back(special);
    polar.push_back(Eigen::Matrix3d::Zero());
  }
  // Mix the special matrices into batches of regular ones; 2028 is not a multiple of the lane count.
  std::vector<size_t> order(F.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<Eigen::Matrix3d> F_mixed, polar_mixed;
  for (size_t i : order) F_mixed.push_back(F[i]), polar_mixed.push_back(polar[i]);
  for (size_t n : {F_mixed.size(), size_t(13), size_t(1)}) {
    std::vector<Eigen::Matrix3d> R(n);
    rotations_from_deformations(F_mixed.data(), R.data(), n);
    double worst_scalar = 0, worst_polar = 0;
    for (size_t i = 0; i < n; ++i) {
      REQUIRE(is_rotation(R[i]));
      worst_scalar = std::max(worst_scalar, (R[i] - rotation_from_deformation(F_mixed[i])).norm());
      if (polar_mixed[i].squaredNorm() > 0)
        worst_polar = std::max(worst_polar, (R[i] - polar_mixed[i]).norm());
    }
    CHECK(worst_scalar < 1e-14);
    CHECK(worst_polar < 1e-9); // the inversion sweep's tolerance; regular F below
  }
  std::vector<Eigen::Matrix3d> R(2000);
  rotations_from_deformations(F.data(), R.data(), 2000);
  double worst = 0;
  for (int i = 0; i < 2000; ++i) worst = std::max(worst, (R[i] - polar[i]).norm());
  CHECK(worst < 1e-12);
}

TEST_CASE("P2 shape functions integrate to -V/20 (corners) and V/5 (edges); masses positive", "[fem][mass]")
{
  const Eigen::VectorXd w = shape_function_integrals(2);
  for (int a = 0; a < 4; ++a) CHECK(w[a] == Approx(-1.0 / 20));
  for (int a = 4; a < 10; ++a) CHECK(w[a] == Approx(1.0 / 5));
  const Eigen::MatrixXd Mc = reference_mass(2, MassLumping::Consistent);
  CHECK(Mc.sum() == Approx(1.0));
  CHECK(Mc(0, 0) == Approx(6.0 / 420));
  CHECK(Mc(4, 4) == Approx(32.0 / 420));
  CHECK((Mc - Mc.transpose()).norm() < 1e-15);
  CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Mc).eigenvalues().minCoeff() > 0);
  const Eigen::MatrixXd Mh = reference_mass(2, MassLumping::Lumped);
  CHECK(Mh.isDiagonal());
  CHECK(Mh.sum() == Approx(1.0));
  CHECK(Mh.diagonal().minCoeff() > 0);
  CHECK(Mh(0, 0) == Approx(1.0 / 36));
}

TEST_CASE("rigidly rotated mesh at rest: zero corotational force, spurious linear force",
          "[fem][corotational]")
{
  for (int order : {1, 2}) {
    INFO("order " << order);
    FemSettings s;
    s.young                    = 1e6;
    const TetMesh         mesh = jittered_box(order);
    const Eigen::Matrix3d Q    = some_rotation();
    const Eigen::Vector3d t(0.4, -1.0, 2.0);
    std::vector<double>   x(mesh.nodes.size());
    double                scale = 0;
    for (int i = 0; i < mesh.node_count(); ++i)
      Eigen::Vector3d::Map(&x[3 * i]) = Q * Eigen::Vector3d::Map(&mesh.nodes[3 * i]) + t;
    s.corotational        = true;
    const FemModel corot  = make_fem_model(mesh, s);
    s.corotational        = false;
    const FemModel linear = make_fem_model(mesh, s);
    // Force scale: what a unit-size displacement would produce (E * characteristic area).
    scale            = s.young * 0.1;
    const auto fc    = elastic_forces(corot, x.data());
    const auto fl    = elastic_forces(linear, x.data());
    double     max_c = 0, max_l = 0;
    for (size_t k = 0; k < fc.size(); ++k) {
      max_c = std::max(max_c, std::fabs(fc[k]));
      max_l = std::max(max_l, std::fabs(fl[k]));
    }
    CHECK(max_c < 1e-9 * scale);
    CHECK(max_l > 1e-2 * scale);
    CHECK(fem_energy(corot, x.data(), std::vector<double>(x.size(), 0.0).data()).elastic < 1e-12 * s.young);
  }
}

TEST_CASE("patch test: a linear displacement field is reproduced exactly by P1 and P2", "[fem][patch]")
{
  for (int order : {1, 2}) {
    INFO("order " << order);
    const TetMesh mesh = jittered_box(order);
    FemSettings   s;
    s.corotational    = false;
    s.poisson         = 0.35;
    const FemModel  m = make_fem_model(mesh, s);
    Eigen::Matrix3d G;
    G << 1e-3, 2e-3, -1e-3, 0.5e-3, -2e-3, 1e-3, 3e-3, 1e-3, 0.7e-3;
    const Eigen::Vector3d b(0.01, -0.02, 0.03);
    auto exact = [&](int i) { return Eigen::Vector3d(G * Eigen::Vector3d::Map(&mesh.nodes[3 * i]) + b); };
    // Boundary nodes prescribed (fixed: dx = 0 at the exact value), interior nodes solved from K u = 0.
    std::vector<char>   boundary(mesh.node_count(), 0);
    std::vector<double> x(mesh.nodes);
    const double        ext[3] = {1.0, 0.8, 0.6};
    for (int i = 0; i < mesh.node_count(); ++i) {
      for (int d = 0; d < 3; ++d)
        if (mesh.nodes[3 * i + d] < 1e-9 || mesh.nodes[3 * i + d] > ext[d] - 1e-9) boundary[i] = 1;
      if (boundary[i]) Eigen::Vector3d::Map(&x[3 * i]) += exact(i);
    }
    // Static Newton step from x: K dx = f(x).
    const physics::StepCoefficients c{1, 0, 0, 0, 1};
    const auto sys      = fem_test::assemble(m, boundary, c, x, std::vector<double>(x.size(), 0.0), {}, 0);
    const auto dx       = fem_test::solve(sys);
    double     err      = 0;
    int        interior = 0;
    for (int i = 0; i < mesh.node_count(); ++i) {
      if (boundary[i]) continue;
      ++interior;
      const Eigen::Vector3d u =
        Eigen::Vector3d::Map(&x[3 * i]) + dx.segment<3>(3 * i) - Eigen::Vector3d::Map(&mesh.nodes[3 * i]);
      err = std::max(err, (u - exact(i)).norm());
    }
    CHECK(interior > 0);
    CHECK(err < 1e-12);
    // And the internal nodal forces of the exact field vanish at interior nodes.
    for (int i = 0; i < mesh.node_count(); ++i)
      Eigen::Vector3d::Map(&x[3 * i]) = Eigen::Vector3d::Map(&mesh.nodes[3 * i]) + exact(i);
    const auto f    = elastic_forces(m, x.data());
    double     fmax = 0;
    for (int i = 0; i < mesh.node_count(); ++i)
      if (!boundary[i]) fmax = std::max(fmax, Eigen::Vector3d::Map(&f[3 * i]).norm());
    CHECK(fmax < 1e-8 * s.young * 1e-3);
  }
}

TEST_CASE("P1 fast kernel (rotated gradients) equals the generic K0 kernel", "[fem][kernel]")
{
  const TetMesh mesh = jittered_box(1);
  FemSettings   s;
  s.poisson        = 0.42;
  FemModel fast    = make_fem_model(mesh, s);
  FemModel generic = fast;
  generic.gradients.clear(); // falls back to the stored-K0 kernel
  const auto        elements = fem_test::all_elements(fast);
  std::vector<char> fixed(mesh.node_count(), 0);
  fixed[0] = fixed[5]     = 1;
  const BlockPattern    p = make_block_pattern(fast, elements, fixed, 0, mesh.node_count(), true);
  std::vector<double>   x(mesh.nodes), v(x.size());
  const Eigen::Matrix3d Q = some_rotation();
  for (int i = 0; i < mesh.node_count(); ++i) {
    Eigen::Vector3d::Map(&x[3 * i]) =
      Q * (Eigen::Vector3d::Map(&mesh.nodes[3 * i]) * 1.1 + Eigen::Vector3d(0, 0.05 * mesh.nodes[3 * i], 0));
    v[3 * i] = std::sin(i * 0.3), v[3 * i + 1] = std::cos(i * 0.7), v[3 * i + 2] = 0.1 * i;
  }
  const StepCoefficients c = implicit_euler_coefficients(0.02, 0.3, 0.001);
  std::vector<double>    va, vb, ra(x.size(), 0.0), rb(x.size(), 0.0);
  reset_block_values(p, va);
  reset_block_values(p, vb);
  assemble_elements(fast, elements, x.data(), v.data(), c, &p, va.data(), ra.data(), nullptr,
                    ElementKernel::Scalar);
  assemble_elements(generic, elements, x.data(), v.data(), c, &p, vb.data(), rb.data(), nullptr,
                    ElementKernel::Scalar);
  double dv = 0, sv = 0, dr = 0, sr = 0;
  for (size_t k = 0; k < va.size(); ++k)
    dv = std::max(dv, std::fabs(va[k] - vb[k])), sv = std::max(sv, std::fabs(vb[k]));
  for (size_t k = 0; k < ra.size(); ++k)
    dr = std::max(dr, std::fabs(ra[k] - rb[k])), sr = std::max(sr, std::fabs(rb[k]));
  CHECK(dv < 1e-12 * sv);
  CHECK(dr < 1e-12 * sr);
  CHECK(sr > 0);
}

TEST_CASE("element loop overwrites the block values: one first write per block, no reset needed",
          "[fem][kernel]")
{
  for (int order : {1, 2})
    for (bool merge : {true, false})
      for (bool drop : {false, true}) {
        INFO("order " << order << " merge " << merge << " drop lower " << drop);
        const TetMesh     mesh     = jittered_box(order);
        const FemModel    m        = make_fem_model(mesh, FemSettings{});
        const auto        elements = fem_test::all_elements(m);
        std::vector<char> fixed(mesh.node_count(), 0);
        fixed[0] = fixed[5] = 1;
        LowerTriangle lower;
        lower.drop           = drop;
        const BlockPattern p = make_block_pattern(m, elements, fixed, 0, mesh.node_count(), merge, lower);
        // Every element block has exactly one entry marked as its first write, the earliest one.
        std::vector<int> firsts(p.rows.size(), 0);
        for (int s : p.element_slots)
          if (s >= 0 && (s & kFirstContribution)) ++firsts[s & kSlotIndexMask];
        for (int s : p.identity_slots) {
          CHECK(firsts[s] == 0);
          firsts[s] = 1;
        }
        CHECK(std::count(firsts.begin(), firsts.end(), 1) == static_cast<long>(p.rows.size()));
        std::vector<double> x(mesh.nodes), v(x.size());
        for (size_t k = 0; k < x.size(); ++k) x[k] *= 1.02, v[k] = std::sin(0.37 * k);
        const StepCoefficients c = implicit_euler_coefficients(0.02, 0.3, 0.001);
        std::vector<double>    fresh, rhs(x.size(), 0.0);
        reset_block_values(p, fresh);
        assemble_elements(m, elements, x.data(), v.data(), c, &p, fresh.data(), rhs.data());
        // Garbage in the element blocks, then two assemblies without a reset: the same bits.
        std::vector<double> reused(fresh.size(), std::nan(""));
        reset_block_values(p, reused);
        for (int pass = 0; pass < 2; ++pass)
          assemble_elements(m, elements, x.data(), v.data(), c, &p, reused.data(), rhs.data());
        CHECK(reused == fresh);
        // Against the unmerged assembly (one COO block per element block, nothing shared) summed here.
        if (merge) {
          const BlockPattern  u = make_block_pattern(m, elements, fixed, 0, mesh.node_count(), false, lower);
          std::vector<double> uv, urhs(x.size(), 0.0);
          reset_block_values(u, uv);
          assemble_elements(m, elements, x.data(), v.data(), c, &u, uv.data(), urhs.data());
          std::map<std::pair<int, int>, Eigen::Matrix<double, 9, 1>> sum;
          for (size_t k = 0; k < u.rows.size(); ++k) {
            auto it = sum.try_emplace({u.rows[k], u.cols[k]}, Eigen::Matrix<double, 9, 1>::Zero()).first;
            it->second += Eigen::Matrix<double, 9, 1>::Map(&uv[9 * k]);
          }
          REQUIRE(sum.size() == p.rows.size());
          double diff = 0, scale = 0;
          for (size_t k = 0; k < p.rows.size(); ++k) {
            const Eigen::Matrix<double, 9, 1> &ref = sum.at({p.rows[k], p.cols[k]});
            diff =
              std::max(diff, (Eigen::Matrix<double, 9, 1>::Map(&fresh[9 * k]) - ref).cwiseAbs().maxCoeff());
            scale = std::max(scale, ref.cwiseAbs().maxCoeff());
          }
          CHECK(diff <= 1e-13 * scale);
        }
      }
}

TEST_CASE("upper-triangle patterns: kept blocks equal the full assembly's, lower ones dropped",
          "[fem][kernel]")
{
  for (int order : {1, 2}) {
    INFO("order " << order);
    const TetMesh     mesh     = jittered_box(order);
    const FemModel    m        = make_fem_model(mesh, FemSettings{});
    const auto        elements = fem_test::all_elements(m);
    std::vector<char> fixed(mesh.node_count(), 0);
    fixed[0] = fixed[5]     = 1;
    const int          n    = mesh.node_count();
    const BlockPattern full = make_block_pattern(m, elements, fixed, 0, n, true);
    LowerTriangle      drop;
    drop.drop            = true;
    LowerTriangle across = drop;
    across.part_offsets  = {0, n / 3, n}; // two parts: lower blocks between them are kept
    std::vector<double>   x(mesh.nodes), v(x.size());
    const Eigen::Matrix3d Q = some_rotation();
    for (int i = 0; i < n; ++i) {
      Eigen::Vector3d::Map(&x[3 * i]) = Q * (Eigen::Vector3d::Map(&mesh.nodes[3 * i]) * 1.05);
      v[3 * i] = std::sin(i * 0.3), v[3 * i + 1] = std::cos(i * 0.7), v[3 * i + 2] = 0.1 * i;
    }
    const StepCoefficients c = implicit_euler_coefficients(0.02, 0.3, 0.001);
    std::vector<double>    vf, rf(x.size(), 0.0);
    reset_block_values(full, vf);
    assemble_elements(m, elements, x.data(), v.data(), c, &full, vf.data(), rf.data());
    std::map<std::pair<int, int>, int> full_slot;
    for (size_t k = 0; k < full.rows.size(); ++k)
      full_slot[{full.rows[k], full.cols[k]}] = static_cast<int>(k);
    for (const LowerTriangle &lower : {drop, across}) {
      const BlockPattern  p = make_block_pattern(m, elements, fixed, 0, n, true, lower);
      std::vector<double> vp, rp(x.size(), 0.0);
      reset_block_values(p, vp);
      assemble_elements(m, elements, x.data(), v.data(), c, &p, vp.data(), rp.data());
      size_t expected = 0;
      for (size_t k = 0; k < full.rows.size(); ++k) {
        const int  r = full.rows[k], q = full.cols[k];
        const bool crosses = !lower.part_offsets.empty() && ((r < n / 3) != (q < n / 3));
        expected += (r <= q || crosses) ? 1 : 0;
      }
      CHECK(p.rows.size() == expected);
      double diff = 0, scale = 0;
      for (size_t k = 0; k < p.rows.size(); ++k) {
        const bool crosses = !lower.part_offsets.empty() && ((p.rows[k] < n / 3) != (p.cols[k] < n / 3));
        CHECK((p.rows[k] <= p.cols[k] || crosses));
        const int f = full_slot.at({p.rows[k], p.cols[k]});
        for (int j = 0; j < 9; ++j)
          diff  = std::max(diff, std::fabs(vp[9 * k + j] - vf[9 * f + j])),
          scale = std::max(scale, std::fabs(vf[9 * f + j]));
      }
      CHECK(diff == 0.0);
      CHECK(scale > 0);
      CHECK(rp == rf);
    }
  }
}
