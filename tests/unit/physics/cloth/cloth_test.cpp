// Cloth: equilibrium, spring relaxation, definiteness of the system matrix, stability with stiff springs,
// bad input.
#include "physics/cloth_model.hpp"
#include "physics/cloth_springs.hpp"
#include "physics/cloth_step.hpp"
#include "sparse_solver.hpp"

#include <catch2/catch.hpp>
#include <Eigen/Dense>
#include <cmath>

using namespace physics;

namespace {

Eigen::MatrixXd dense(const ClothSystem &sys)
{
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(3 * sys.n_particles, 3 * sys.n_particles);
  for (size_t k = 0; k < sys.block_row.size(); ++k)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        A(3 * sys.block_row[k] + i, 3 * sys.block_col[k] + j) += sys.block_values[9 * k + 3 * i + j];
  return A;
}

double max_speed(const Cloth &c)
{
  double v = 0;
  for (const auto &x : c.velocity) v = std::max(v, x.norm());
  return v;
}

} // namespace

TEST_CASE("hanging cloth settles and then stays at rest with balanced forces", "[cloth]")
{
  ClothOptions opt;
  opt.n = 8, opt.size = 0.5, opt.hanging = true, opt.pins = ClothPins::TopRow, opt.k_stretch = 200,
  opt.k_shear = 20, opt.k_bend = 2, opt.damping = 0.05;
  Cloth       cloth = make_cloth(opt);
  ClothSystem sys   = make_cloth_system(cloth);
  auto        ref   = sparse_solver_for(sys);
  auto        lin   = ref.adapter();
  ClothParams params;
  for (int n = 0; n < 1500; ++n) REQUIRE(cloth_step(cloth, sys, params, lin).converged);
  CHECK(max_speed(cloth) < 1e-6);
  std::vector<Eigen::Vector3d> f;
  cloth_forces(cloth, f);
  double worst = 0;
  for (const auto &x : f) worst = std::max(worst, x.norm());
  const double weight = opt.total_mass / (opt.n * opt.n) * 9.81;
  CHECK(worst < 1e-5 * weight);
  // At rest it stays at rest: further steps move nothing.
  const std::vector<Eigen::Vector3d> before = cloth.position;
  for (int n = 0; n < 100; ++n) cloth_step(cloth, sys, params, lin);
  double moved = 0;
  for (int p = 0; p < cloth.particle_count(); ++p)
    moved = std::max(moved, (cloth.position[p] - before[p]).norm());
  CHECK(moved < 1e-9);
  CHECK(max_stretch_ratio(cloth) > 1.0); // it did sag under its weight
}

TEST_CASE("a stretched spring relaxes towards its rest length", "[cloth]")
{
  Cloth c;
  c.n        = 0;
  c.position = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1.5, 0, 0)};
  c.velocity.assign(2, Eigen::Vector3d::Zero());
  c.mass    = {1.0, 1.0};
  c.fixed   = {1, 0};
  c.gravity = Eigen::Vector3d::Zero();
  c.springs = {Spring{0, 1, 1.0, 100.0, SpringKind::Stretch}};
  REQUIRE(validate_cloth(c).empty());
  ClothSystem sys = make_cloth_system(c);
  auto        ref = sparse_solver_for(sys);
  auto        lin = ref.adapter();
  ClothParams params;
  params.dt           = 0.01;
  double prev         = 0.5;
  int    non_monotone = 0;
  for (int n = 0; n < 2000; ++n) {
    cloth_step(c, sys, params, lin);
    const double excess = std::abs((c.position[1] - c.position[0]).norm() - 1.0);
    non_monotone += excess > prev + 1e-12 && n < 5; // the first steps head straight for the rest length
    prev = excess;
  }
  CHECK(non_monotone == 0);
  CHECK(prev < 1e-3);
  // Backward Euler on x'' = -w^2 x: energy ratio per step 1/(1 + w^2 h^2), so it decays.
  CHECK(cloth_energy(c) < 0.5 * 100 * 0.25 * 1e-3);
}

TEST_CASE("system matrix is symmetric positive definite, also with compressed springs", "[cloth]")
{
  ClothOptions opt;
  opt.n = 6, opt.k_stretch = 1e5, opt.k_shear = 1e4, opt.k_bend = 1e3;
  Cloth cloth = make_cloth(opt);
  // Crumple it: shrink to 70 % and add noise, so many springs are compressed.
  srand(7);
  for (auto &x : cloth.position) x = 0.7 * x + 0.01 * Eigen::Vector3d::Random();
  ClothParams params;
  params.dt       = 1.0 / 30;
  ClothSystem sys = make_cloth_system(cloth);
  assemble_cloth_system(cloth, params, sys);
  Eigen::MatrixXd A = dense(sys);
  CHECK((A - A.transpose()).norm() < 1e-12 * A.norm());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A);
  CHECK(eig.eigenvalues().minCoeff() > 0);
  // Without Choi & Ko's treatment the exact Jacobian of the compressed springs makes it indefinite.
  params.choi_ko = false;
  assemble_cloth_system(cloth, params, sys);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig_exact(dense(sys));
  CHECK(eig_exact.eigenvalues().minCoeff() < 0);
}

TEST_CASE("one spring's force and Jacobians match finite differences; coincident ends have none", "[cloth]")
{
  // The spring kernel (spring_terms_lane, through linearise_spring) against central differences of
  // f_a = k (l - L) d + c (d.(v_b - v_a)) d: K = -df_a/dx_a of the elastic part (the damping force's
  // change of direction is left out, as in Baraff & Witkin), D = -df_a/dv_a.
  Spring s;
  s.a = 0, s.b = 1, s.rest_length = 0.1, s.stiffness = 300;
  const double c     = 0.7;
  auto         force = [&](const Eigen::Vector3d &xa, const Eigen::Vector3d &xb, const Eigen::Vector3d &va,
                   const Eigen::Vector3d &vb, double damping) {
    const Eigen::Vector3d d = (xb - xa).normalized();
    return Eigen::Vector3d((s.stiffness * ((xb - xa).norm() - s.rest_length) + damping * d.dot(vb - va)) * d);
  };
  const Eigen::Vector3d xa(0.01, -0.02, 0.03), va(0.3, -0.1, 0.2), vb(-0.2, 0.4, 0.1);
  for (const double length : {0.13, 0.07}) { // stretched, compressed
    const Eigen::Vector3d xb = xa + length * Eigen::Vector3d(2, -1, 2) / 3.0;
    Eigen::Matrix3d       K, D;
    const double          e = 1e-6;
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d dx = e * Eigen::Vector3d::Unit(j);
      K.col(j)                 = -(force(xa + dx, xb, va, vb, 0) - force(xa - dx, xb, va, vb, 0)) / (2 * e);
      D.col(j)                 = -(force(xa, xb, va + dx, vb, c) - force(xa, xb, va - dx, vb, c)) / (2 * e);
    }
    const SpringLinearisation exact = linearise_spring(s, xa, xb, va, vb, c, false);
    CHECK((exact.force_on_a - force(xa, xb, va, vb, c)).norm() < 1e-12 * force(xa, xb, va, vb, c).norm());
    CHECK((exact.stiffness - K).norm() < 1e-6 * K.norm());
    CHECK((exact.damping - D).norm() < 1e-6 * D.norm());
    // Choi-Ko: a compressed spring keeps only k d d^T
    const SpringLinearisation ck = linearise_spring(s, xa, xb, va, vb, c, true);
    const Eigen::Vector3d     d  = (xb - xa).normalized();
    if (length < s.rest_length)
      CHECK((ck.stiffness - s.stiffness * d * d.transpose()).norm() < 1e-12 * s.stiffness);
    else CHECK((ck.stiffness - exact.stiffness).norm() == 0);
  }
  const SpringTerms none = spring_terms(s, xa, xa, va, vb, c);
  CHECK(none.direction.norm() == 0);
  CHECK(none.force_on_a.norm() == 0);
  CHECK(none.k_iso == s.stiffness);
  CHECK(none.k_dir == 0);
}

TEST_CASE("assembled system equals M + h D + h^2 K and h (f - h K v) built from each spring's Jacobians",
          "[cloth]")
{
  ClothOptions opt;
  opt.n = 5, opt.damping = 0.3;
  Cloth cloth = make_cloth(opt);
  srand(11);
  for (auto &x : cloth.position)
    x = 0.8 * x + 0.02 * Eigen::Vector3d::Random(); // some springs compressed, some stretched
  for (auto &v : cloth.velocity) v = Eigen::Vector3d::Random();
  ClothParams params;
  params.dt        = 1.0 / 60;
  const double h   = params.dt;
  ClothSystem  sys = make_cloth_system(cloth);
  assemble_cloth_system(cloth, params, sys);
  // Reference: dense matrices from linearise_spring, pinned rows and columns reduced to M.
  const int       n = cloth.particle_count();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3 * n, 3 * n), D = K;
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * n), v(3 * n);
  for (int p = 0; p < n; ++p)
    f.segment<3>(3 * p) = cloth.mass[p] * cloth.gravity, v.segment<3>(3 * p) = cloth.velocity[p];
  for (const Spring &sp : cloth.springs) {
    const SpringLinearisation lin =
      linearise_spring(sp, cloth.position[sp.a], cloth.position[sp.b], cloth.velocity[sp.a],
                       cloth.velocity[sp.b], cloth.damping);
    for (int a : {sp.a, sp.b})
      for (int b : {sp.a, sp.b}) {
        const double s = a == b ? 1.0 : -1.0;
        K.block<3, 3>(3 * a, 3 * b) += s * lin.stiffness;
        D.block<3, 3>(3 * a, 3 * b) += s * lin.damping;
      }
    f.segment<3>(3 * sp.a) += lin.force_on_a;
    f.segment<3>(3 * sp.b) -= lin.force_on_a;
  }
  Eigen::MatrixXd A   = h * D + h * h * K;
  Eigen::VectorXd rhs = h * (f - h * K * v);
  for (int p = 0; p < n; ++p) {
    A.block<3, 3>(3 * p, 3 * p) += cloth.mass[p] * Eigen::Matrix3d::Identity();
    if (!cloth.fixed[p]) continue;
    A.block(3 * p, 0, 3, 3 * n).setZero(), A.block(0, 3 * p, 3 * n, 3).setZero();
    A.block<3, 3>(3 * p, 3 * p) = cloth.mass[p] * Eigen::Matrix3d::Identity();
    rhs.segment<3>(3 * p).setZero();
  }
  CHECK((dense(sys) - A).norm() < 1e-12 * A.norm());
  CHECK((Eigen::Map<const Eigen::VectorXd>(sys.rhs.data(), 3 * n) - rhs).norm() < 1e-12 * rhs.norm());
}

TEST_CASE("rows assembled in parts, upper triangle only, add up to the whole system", "[cloth]")
{
  // What each rank of the driver does: its own rows, only the spring blocks its Mat type keeps.
  ClothOptions opt;
  opt.n = 6, opt.damping = 0.2, opt.pins = ClothPins::FourCorners;
  Cloth cloth = make_cloth(opt);
  srand(5);
  for (auto &x : cloth.position) x = 0.85 * x + 0.02 * Eigen::Vector3d::Random();
  for (auto &v : cloth.velocity) v = Eigen::Vector3d::Random();
  ClothParams params;
  ClothSystem whole = make_cloth_system(cloth);
  assemble_cloth_system(cloth, params, whole);
  const Eigen::MatrixXd A               = dense(whole);
  const int             n               = cloth.particle_count();
  Eigen::MatrixXd       upper_sum       = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  Eigen::VectorXd       rhs_sum         = Eigen::VectorXd::Zero(3 * n);
  size_t                springs_visited = 0, blocks = 0;
  double                stretch_max = 0;
  for (int part = 0; part < 3; ++part) {
    std::vector<char> own(n);
    for (int p = 0; p < n; ++p) own[p] = (p * 7) % 3 == part; // interleaved rows: many springs cross parts
    ClothSystem sys = make_cloth_system(cloth, own, [](int row, int col) { return row < col; });
    assemble_cloth_system(cloth, params, sys);
    upper_sum += dense(sys);
    for (int p = 0; p < n; ++p)
      if (own[p]) rhs_sum.segment<3>(3 * p) = Eigen::Map<const Eigen::Vector3d>(&sys.rhs[3 * p]);
    for (size_t k = 0; k < sys.block_row.size(); ++k)
      CHECK((own[sys.block_row[k]] && sys.block_row[k] <= sys.block_col[k]));
    springs_visited += sys.springs.size();
    blocks += sys.block_row.size();
    for (int k : sys.stretch_springs) CHECK(cloth.springs[k].kind == SpringKind::Stretch);
    stretch_max =
      std::max(stretch_max, max_stretch_ratio(cloth, sys.stretch_springs)); // the driver's all-reduce
  }
  CHECK(stretch_max == max_stretch_ratio(cloth)); // the parts' stretch checks cover every stretch spring
  CHECK(stretch_max > 1.0);
  Eigen::MatrixXd upper = A; // the block upper triangle
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < i; ++j) upper.block<3, 3>(3 * i, 3 * j).setZero();
  CHECK((upper_sum - upper).norm() < 1e-14 * A.norm());
  CHECK((rhs_sum - Eigen::Map<const Eigen::VectorXd>(whole.rhs.data(), 3 * n)).norm() <
        1e-14 * rhs_sum.norm());
  CHECK(blocks == (size_t)n + cloth.springs.size()); // one block per spring, one per particle
  CHECK(springs_visited > cloth.springs.size());     // springs between parts are visited on both sides
  CHECK(springs_visited < 2 * cloth.springs.size());
  CHECK_THROWS_WITH(make_cloth_system(cloth, std::vector<char>(3, 1), [](int, int) { return true; }),
                    Catch::Contains("one ownership flag per particle"));
}

TEST_CASE("stiff cloth at dt 1/30 stays finite and bounded", "[cloth]")
{
  ClothOptions opt;
  opt.n = 16, opt.k_stretch = 1e6, opt.k_shear = 1e5, opt.k_bend = 1e4;
  Cloth cloth          = make_cloth(opt);
  cloth.sphere.enabled = true;
  cloth.sphere.centre  = Eigen::Vector3d(0, -0.4, 0.1);
  ClothSystem sys      = make_cloth_system(cloth);
  auto        ref      = sparse_solver_for(sys);
  auto        lin      = ref.adapter();
  ClothParams params;
  params.dt    = 1.0 / 30;
  int contacts = 0;
  for (int n = 0; n < 90; ++n) {
    const ClothStepReport r = cloth_step(cloth, sys, params, lin);
    REQUIRE(r.converged);
    contacts += r.contacts;
  }
  bool finite = true;
  for (int p = 0; p < cloth.particle_count(); ++p)
    finite &= cloth.position[p].allFinite() && cloth.velocity[p].allFinite();
  CHECK(finite);
  CHECK(max_stretch_ratio(cloth) < 1.05);
  CHECK(contacts > 0);
  for (const auto &x : cloth.position) CHECK((x - cloth.sphere.centre).norm() >= cloth.sphere.radius - 1e-12);
}

TEST_CASE("bad cloth input is rejected with a clear message", "[cloth][errors]")
{
  CHECK_THROWS_WITH(make_cloth(ClothOptions{1}), Catch::Contains("at least 2 x 2"));
  ClothOptions neg;
  neg.k_stretch = -1;
  CHECK_THROWS_WITH(make_cloth(neg), Catch::Contains("non-negative"));
  ClothOptions small;
  small.n = 4;
  Cloth c = make_cloth(small);
  CHECK(validate_cloth(c).empty());
  Cloth zero   = c;
  zero.mass[3] = 0;
  CHECK_THAT(validate_cloth(zero), Catch::Contains("mass must be positive"));
  Cloth bad_spring        = c;
  bad_spring.springs[0].b = 99;
  CHECK_THAT(validate_cloth(bad_spring), Catch::Contains("out of range"));
  Cloth nan_state           = c;
  nan_state.position[2].x() = NAN;
  CHECK_THAT(validate_cloth(nan_state), Catch::Contains("not finite"));
  ClothParams p;
  p.dt = 0;
  CHECK_THAT(validate_params(p), Catch::Contains("time step"));
}
