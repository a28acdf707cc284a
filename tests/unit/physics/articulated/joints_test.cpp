// The joint matrix, the correction loop, loops and bad input.
#include "dense_solver.hpp"
#include "physics/articulated_scenes.hpp"
#include "physics/articulated_step.hpp"
#include "physics/kinematic_loops.hpp"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

using namespace physics;

namespace {

// J (3 rows per joint, 6 columns per body: linear then angular velocity) built directly from the geometry.
Eigen::MatrixXd constraint_jacobian(const ArticulatedScene &scene)
{
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3 * scene.joints.size(), 6 * scene.bodies.size());
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    const BallJoint &jt = scene.joints[j];
    for (int end = 0; end < 2; ++end) {
      const int body = end == 0 ? jt.body_a : jt.body_b;
      if (body == kWorld) continue;
      const double          s = end == 0 ? 1.0 : -1.0;
      const Eigen::Vector3d r = joint_arm(scene, body, end == 0 ? jt.anchor_a : jt.anchor_b);
      Eigen::Matrix3d       rx;
      rx << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
      J.block(3 * j, 6 * body, 3, 3)     = s * Eigen::Matrix3d::Identity();
      J.block(3 * j, 6 * body + 3, 3, 3) = -s * rx; // u = v + w x r = v - [r]x w
    }
  }
  return J;
}

Eigen::MatrixXd inverse_mass(const ArticulatedScene &scene)
{
  Eigen::MatrixXd Minv = Eigen::MatrixXd::Zero(6 * scene.bodies.size(), 6 * scene.bodies.size());
  for (size_t i = 0; i < scene.bodies.size(); ++i) {
    Minv.block(6 * i, 6 * i, 3, 3)         = Eigen::Matrix3d::Identity() / scene.bodies[i].mass;
    Minv.block(6 * i + 3, 6 * i + 3, 3, 3) = world_inverse_inertia(scene.bodies[i]);
  }
  return Minv;
}

struct RunStats {
  bool   all_converged = true, finite = true, singular = false;
  double worst_error = 0, energy_growth = 0;
  long   corrections = 0;
};

RunStats run(ArticulatedScene &scene, ArticulatedParams params, int steps)
{
  ArticulatedSolver s   = make_articulated_solver(scene, params);
  DenseBlockSolver  ref = dense_solver_for(s.pattern);
  auto              lin = ref.adapter();
  RunStats          st;
  const double      e0 = total_energy(scene);
  for (int n = 0; n < steps; ++n) {
    const ArticulatedStepReport r = articulated_step(scene, s, params, lin);
    st.all_converged &= r.converged;
    st.singular |= r.singular_detected;
    st.worst_error = std::max(st.worst_error, r.joint_error);
    st.corrections += r.corrections;
    for (const RigidBody &b : scene.bodies)
      st.finite &= b.position.allFinite() && b.velocity.allFinite() && b.angular_velocity.allFinite();
    st.energy_growth = std::max(st.energy_growth, total_energy(scene) - e0);
  }
  return st;
}

} // namespace

TEST_CASE("joint matrix values equal J M^-1 J^T built densely", "[articulated]")
{
  BridgeOptions opt;
  opt.chains = 3, opt.links = 6, opt.tie_every = 2;
  ArticulatedScene scene = make_bridge(opt);
  // Turn and spin the planks so that every block term is exercised.
  for (size_t i = 0; i < scene.bodies.size(); ++i)
    scene.bodies[i].orientation =
      rotated(scene.bodies[i].orientation, Eigen::Vector3d(0.3, -0.7 + 0.1 * i, 0.2), 1.0);
  const JointMatrixPattern p = build_joint_matrix_pattern(scene);
  std::vector<double>      values;
  fill_joint_matrix(scene, p, 0.0, values);
  const Eigen::MatrixXd J = constraint_jacobian(scene);
  const Eigen::MatrixXd A = J * inverse_mass(scene) * J.transpose();
  Eigen::MatrixXd       B = Eigen::MatrixXd::Zero(A.rows(), A.cols());
  for (size_t k = 0; k < p.block_row.size(); ++k)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        B(3 * p.block_row[k] + i, 3 * p.block_col[k] + j) += values[9 * k + 3 * i + j];
  CHECK((A - B).norm() < 1e-12 * A.norm());
  // The pattern holds exactly the nonzero blocks, both triangles.
  int nonzero_blocks = 0;
  for (int r = 0; r < A.rows() / 3; ++r)
    for (int c = 0; c < A.cols() / 3; ++c) nonzero_blocks += A.block(3 * r, 3 * c, 3, 3).norm() > 0;
  CHECK(nonzero_blocks == static_cast<int>(p.block_row.size()));
  CHECK(p.block_row.size() % 2 == static_cast<size_t>(p.n_joints) % 2);
}

TEST_CASE("chain: joint error below tolerance after every step, energy does not grow", "[articulated]")
{
  ChainOptions opt;
  opt.links = 10, opt.angle = 0.8;
  ArticulatedScene  scene = make_chain(opt);
  ArticulatedParams params;
  params.dt                 = 1.0 / 60;
  ArticulatedSolver   s     = make_articulated_solver(scene, params);
  DenseBlockSolver    ref   = dense_solver_for(s.pattern);
  auto                lin   = ref.adapter();
  const double        e0    = total_energy(scene);
  const double        scale = 10 * 9.81 * 5.0; // m g (chain length): the energy that swinging moves around
  std::vector<double> energy;
  long                corrections = 0;
  for (int n = 0; n < 600; ++n) {
    const ArticulatedStepReport r = articulated_step(scene, s, params, lin);
    REQUIRE(r.converged);
    REQUIRE(r.joint_error < params.joint_tol);
    corrections += r.corrections;
    energy.push_back(total_energy(scene));
  }
  // Symplectic Euler lets the energy oscillate by O(dt) but not drift upwards; the velocity projection
  // only removes energy.
  double first = 0, last = 0, peak = -1e300;
  for (int n = 0; n < 100; ++n) first += energy[n] / 100, last += energy[500 + n] / 100;
  for (double e : energy) peak = std::max(peak, e);
  CHECK(peak - e0 < 0.01 * scale);
  CHECK(last <= first + 1e-3 * scale);
  CHECK(corrections / 600.0 < 3.0); // the seed reports 1-2 corrections per step on average
}

TEST_CASE("four-bar loop: 1000 steps without NaN or drift", "[articulated][loops]")
{
  ArticulatedScene scene = make_four_bar();
  CHECK(loop_closing_joints(scene).size() == 1);
  scene.bodies[0].angular_velocity =
    Eigen::Vector3d(0, 0, 2.0); // crank turning, links follow through joint impulses
  ArticulatedParams params;
  params.dt         = 1.0 / 60;
  const RunStats st = run(scene, params, 1000);
  CHECK(st.finite);
  CHECK(st.all_converged);
  CHECK(st.worst_error < params.joint_tol);
}

TEST_CASE("mass-ratio chain 1e2..1e-2 and 1e-2..1e2 stays jointed", "[articulated]")
{
  for (double ratio : {1e-4, 1e4}) {
    ChainOptions opt;
    opt.links = 12, opt.mass_first = 1e2, opt.mass_last = 1e2 * ratio, opt.angle = 0.6;
    ArticulatedScene  scene = make_chain(opt);
    ArticulatedParams params;
    params.dt              = 1.0 / 240;
    params.refresh_matrix  = true;
    params.max_corrections = 50;
    const RunStats st      = run(scene, params, 240);
    CHECK(st.finite);
    CHECK(st.all_converged);
    CHECK(st.worst_error < params.joint_tol);
  }
}

TEST_CASE("bridge scene has the seed's size and its loops are found", "[articulated][loops]")
{
  const ArticulatedScene scene = make_bridge(BridgeOptions{});
  CHECK(scene.bodies.size() == 13600);
  CHECK(3 * scene.joints.size() == 41613);
  CHECK(loop_closing_joints(scene).size() == 136 + 135);
  CHECK(validate_scene(scene).empty());
  CHECK(max_joint_error(scene) < 1e-9);
  BridgeOptions small;
  small.chains = 4, small.links = 12, small.tie_every = 4;
  ArticulatedScene s  = make_bridge(small);
  const RunStats   st = run(s, ArticulatedParams{}, 120);
  CHECK(st.finite);
  CHECK(st.all_converged);
  CHECK(!st.singular);
}

TEST_CASE("conflicting redundant joints: singular matrix detected and regularised", "[articulated][loops]")
{
  // A rod held at its top by two ball joints at the same body point but world anchors 1 mm apart: the two
  // joints' rows of A are identical (A singular) and their right-hand sides differ (inconsistent).
  ChainOptions opt;
  opt.links = 1, opt.angle = 0.3;
  ArticulatedScene scene = make_chain(opt);
  BallJoint        twin  = scene.joints[0];
  twin.anchor_a += Eigen::Vector3d(1e-3, 0, 0);
  scene.joints.push_back(twin);
  ArticulatedParams params;
  const RunStats    st = run(scene, params, 200);
  CHECK(st.singular);
  CHECK(st.finite);
  // The least-squares compromise sits between the two anchors: each joint is ~0.5 mm off, never more.
  CHECK(st.worst_error < 1e-3);
  CHECK(max_joint_error(scene) > 4e-4);
}

TEST_CASE("consistent redundant joint in a loop is solved once regularised", "[articulated][loops]")
{
  ChainOptions opt;
  opt.links = 3, opt.angle = 0.3;
  ArticulatedScene scene = make_chain(opt);
  scene.joints.push_back(scene.joints[1]); // duplicate: A singular but the right-hand side consistent
  ArticulatedParams params;
  params.regularise_from_start = true;
  const RunStats st            = run(scene, params, 200);
  CHECK(st.finite);
  CHECK(st.all_converged);
}

TEST_CASE("bad articulated input is rejected with a clear message", "[articulated][errors]")
{
  ArticulatedScene scene = make_chain(ChainOptions{});
  CHECK(validate_scene(scene).empty());
  ArticulatedScene missing = scene;
  missing.joints[2].body_b = 42;
  CHECK_THAT(validate_scene(missing), Catch::Contains("names body 42"));
  ArticulatedScene zero_mass = scene;
  zero_mass.bodies[1].mass   = 0;
  CHECK_THAT(validate_scene(zero_mass), Catch::Contains("mass must be positive"));
  ArticulatedScene negative = scene;
  negative.bodies[1].mass   = -2;
  CHECK_THAT(validate_scene(negative), Catch::Contains("mass must be positive"));
  ArticulatedScene flat_inertia             = scene;
  flat_inertia.bodies[0].inertia_body(2, 2) = 0;
  CHECK_THAT(validate_scene(flat_inertia), Catch::Contains("inertia"));
  ArticulatedScene self = scene;
  self.joints[1].body_a = self.joints[1].body_b;
  CHECK_THAT(validate_scene(self), Catch::Contains("itself"));
  ArticulatedParams p;
  p.dt = 0;
  CHECK_THAT(validate_params(p), Catch::Contains("time step"));
  p.dt = -1;
  CHECK_THAT(validate_params(p), Catch::Contains("time step"));
  CHECK_THROWS_AS(make_chain(ChainOptions{0}), std::invalid_argument);
}

TEST_CASE("joint matrix refill: stale values are overwritten, a row subset is filled completely",
          "[articulated]")
{
  BridgeOptions opt;
  opt.chains = 3, opt.links = 6, opt.tie_every = 2;
  ArticulatedScene scene = make_bridge(opt);
  for (size_t i = 0; i < scene.bodies.size(); ++i)
    scene.bodies[i].orientation =
      rotated(scene.bodies[i].orientation, Eigen::Vector3d(0.2, 0.5 - 0.1 * i, -0.3), 1.0);
  const JointMatrixPattern     p  = build_joint_matrix_pattern(scene);
  const size_t                 nb = scene.bodies.size(), nj = scene.joints.size();
  std::vector<Eigen::Matrix3d> inv_inertia(nb);
  std::vector<Eigen::Vector3d> arm_a(nj), arm_b(nj);
  for (size_t i = 0; i < nb; ++i) {
    const Eigen::Matrix3d R = scene.bodies[i].orientation.toRotationMatrix();
    inv_inertia[i]          = R * scene.bodies[i].inertia_body.inverse() * R.transpose();
  }
  for (size_t j = 0; j < nj; ++j) {
    const BallJoint &jt = scene.joints[j];
    arm_a[j]            = jt.body_a == kWorld ? Eigen::Vector3d::Zero()
                                              : Eigen::Vector3d(scene.bodies[jt.body_a].orientation * jt.anchor_a);
    arm_b[j]            = jt.body_b == kWorld ? Eigen::Vector3d::Zero()
                                              : Eigen::Vector3d(scene.bodies[jt.body_b].orientation * jt.anchor_b);
  }
  std::vector<double> full;
  fill_joint_matrix(scene, p, 0.0, inv_inertia, arm_a, arm_b, full);
  // every value is written, none accumulated onto what was there (no zeroing pass any more)
  std::vector<double> again(full.size(), std::nan(""));
  fill_joint_matrix(scene, p, 0.0, inv_inertia, arm_a, arm_b, again);
  CHECK(again == full);
  // the first half of the rows only (as one rank of two would): those rows equal the full fill
  std::vector<int> rows;
  for (int j = 0; j < p.n_joints / 2; ++j) rows.push_back(j);
  const std::vector<char> mask = joint_groups_of_rows(p, rows);
  CHECK(std::count(mask.begin(), mask.end(), 1) < static_cast<long>(mask.size()));
  std::vector<double> part(full.size(), std::nan(""));
  fill_joint_matrix(scene, p, 0.0, inv_inertia, arm_a, arm_b, part, &mask);
  for (size_t k = 0; k < p.block_row.size(); ++k)
    if (p.block_row[k] < p.n_joints / 2)
      for (int e = 0; e < 9; ++e) REQUIRE(part[9 * k + e] == full[9 * k + e]);
}

TEST_CASE(
  "work split over processes: own joints partition, every body counted once, active = bodies of own joints",
  "[articulated][mpi]")
{
  BridgeOptions opt;
  opt.chains = 3, opt.links = 6, opt.tie_every = 2;
  ArticulatedScene scene = make_bridge(opt);
  RigidBody        free_body; // no joints: process 0 moves and counts it
  scene.bodies.push_back(free_body);
  scene.body_sizes.push_back(Eigen::Vector3d::Ones());
  const int        nb = (int)scene.bodies.size(), nj = (int)scene.joints.size(), processes = 3;
  std::vector<int> joint_process(nj);
  for (int j = 0; j < nj; ++j) joint_process[j] = (j * processes) / nj;
  std::vector<int> counted(nb, 0), owned(nj, 0);
  for (int p = 0; p < processes; ++p) {
    const ArticulatedWorkSplit w = split_articulated_work(scene, joint_process, p);
    for (int j : w.own_joints) {
      CHECK(joint_process[j] == p);
      owned[j]++;
      for (int b : {scene.joints[j].body_a, scene.joints[j].body_b})
        if (b != kWorld) CHECK(w.body_active[b]);
    }
    for (int i = 0; i < nb; ++i) {
      counted[i] += w.body_counted[i];
      if (w.body_counted[i]) CHECK(w.body_active[i]);
      CHECK(std::count(w.active_bodies.begin(), w.active_bodies.end(), i) == w.body_active[i]);
    }
    CHECK(std::is_sorted(w.active_bodies.begin(), w.active_bodies.end()));
    for (int j = 0; j < nj; ++j) { // impulse joints: exactly those with an active end
      const BallJoint &jt     = scene.joints[j];
      const bool       active = (jt.body_a != kWorld && w.body_active[jt.body_a]) ||
                          (jt.body_b != kWorld && w.body_active[jt.body_b]);
      CHECK(std::count(w.impulse_joints.begin(), w.impulse_joints.end(), j) == (active ? 1 : 0));
    }
    CHECK(w.body_active[nb - 1] == (p == 0));
  }
  for (int i = 0; i < nb; ++i) CHECK(counted[i] == 1);
  for (int j = 0; j < nj; ++j) CHECK(owned[j] == 1);
  CHECK_THROWS_AS(split_articulated_work(scene, std::vector<int>(nj - 1, 0), 0), std::invalid_argument);
}

TEST_CASE("chain options: a zero or nonfinite link length or width is refused by name", "[articulated]")
{
  for (double bad : {0.0, -1.0, std::nan("")}) {
    ChainOptions length, width;
    length.link_length = bad;
    width.link_width   = bad;
    for (const ChainOptions *o : {&length, &width}) {
      try {
        make_chain(*o);
        FAIL("accepted a link length/width of " << bad);
      } catch (const std::invalid_argument &e) {
        CHECK(std::string(e.what()).find("link length and width must be positive") != std::string::npos);
      }
    }
  }
}
