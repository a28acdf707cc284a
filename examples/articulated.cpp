// Articulated rigid bodies with impulse-based ball joints (physics/articulated_step.hpp); every joint
// impulse solve J M^-1 J^T lambda = rhs goes through PETSc with the configured -mat_type/-ksp_type/-pc_type.
//
//   articulated -options_file options/chain.opts [-steps N] [-dt H] [-mat_type binbcsr] [-ksp_type mcg]
//
// Scenes (-scene): chain (-chain_links, -chain_length, -chain_angle, -chain_mass_first, -chain_mass_last),
// bridge (-bridge_chains, -bridge_links, -bridge_tie_every, -bridge_sag), loop (four-bar linkage).
// Solver options: -joint_tol (m), -max_corrections, -joint_max_halvings, -joint_regularisation, -joint_refresh,
// -velocity_stabilisation, -joint_warm_start (previous step's impulses as initial guesses). Output: a progress
// line every -progress_every steps, -vtk PREFIX (.vtu per -vtk_every steps plus PREFIX.pvd), -dump_matrix FILE
// (J M^-1 J^T of the first step, PETSc binary), -write_positions / -reference_positions FILE (the bodies'
// centres of mass at the end, or their rms and largest distance to such a file's: sim/position_file.h),
// and a final `summary key=value ...` line.
#include "sim/position_file.h"
#include "sim/run_guard.h"
#include "sim/sim_driver.h"
#include "physics/articulated_scenes.hpp"
#include "physics/articulated_step.hpp"
#include "physics/kinematic_loops.hpp"
#include "physics/vtk_writer.hpp"

#include <petscbinbcsr.h>

#include <cmath>
#include <cstring>

static PetscErrorCode BuildScene(MPI_Comm comm, std::string &name, physics::ArticulatedScene &scene)
{
  char      buf[64] = "chain";
  PetscBool set;
  PetscFunctionBegin;
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-scene", buf, sizeof buf, &set));
  name = buf;
  try {
    if (name == "chain") {
      physics::ChainOptions o;
      PetscInt              links = o.links;
      PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-chain_links", &links, nullptr));
      o.links = (int)links;
      PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-chain_length", &o.link_length, nullptr));
      PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-chain_width", &o.link_width, nullptr));
      PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-chain_angle", &o.angle, nullptr));
      PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-chain_mass_first", &o.mass_first, nullptr));
      PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-chain_mass_last", &o.mass_last, nullptr));
      PetscCheck(o.mass_first > 0 && o.mass_last > 0, comm, PETSC_ERR_ARG_OUTOFRANGE,
                 "link masses must be positive, got %g and %g", (double)o.mass_first, (double)o.mass_last);
      scene = physics::make_chain(o);
    } else if (name == "bridge") {
      physics::BridgeOptions o;
      PetscInt               chains = o.chains, links = o.links, tie = o.tie_every;
      PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-bridge_chains", &chains, nullptr));
      PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-bridge_links", &links, nullptr));
      PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-bridge_tie_every", &tie, nullptr));
      PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-bridge_sag", &o.sag, nullptr));
      o.chains = (int)chains, o.links = (int)links, o.tie_every = (int)tie;
      scene = physics::make_bridge(o);
    } else if (name == "loop") {
      scene          = physics::make_four_bar();
      PetscReal spin = 2.0;
      PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-loop_crank_speed", &spin, nullptr));
      scene.bodies[0].angular_velocity = Eigen::Vector3d(0, 0, spin);
    } else {
      SETERRQ(comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "unknown -scene %s (chain, bridge, loop)", buf);
    }
  } catch (const std::invalid_argument &e) {
    SETERRQ(comm, PETSC_ERR_ARG_OUTOFRANGE, "scene %s: %s", buf, e.what());
  }
  const std::string problem = physics::validate_scene(scene);
  PetscCheck(problem.empty(), comm, PETSC_ERR_ARG_WRONG, "scene %s: %s", buf, problem.c_str());
  PetscFunctionReturn(0);
}

// Bodies as boxes (8 corners, one hexahedron each) or as points (-vtk_points, for huge scenes).
static bool WriteFrame(const std::string &path, const physics::ArticulatedScene &scene, bool as_points)
{
  physics::VtkScene      vtk;
  physics::VtkPointField speed{"speed", 1, {}};
  if (as_points) {
    vtk.cell_type = physics::VtkCellType::Vertex, vtk.nodes_per_cell = 1;
    for (size_t i = 0; i < scene.bodies.size(); ++i) {
      for (int k = 0; k < 3; ++k) vtk.points.push_back(scene.bodies[i].position[k]);
      vtk.connectivity.push_back((int)i);
      speed.values.push_back(scene.bodies[i].velocity.norm());
    }
  } else {
    vtk.cell_type = physics::VtkCellType::Hexahedron, vtk.nodes_per_cell = 8;
    const int corner[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                              {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
    for (size_t i = 0; i < scene.bodies.size(); ++i) {
      const physics::RigidBody &b = scene.bodies[i];
      for (int c = 0; c < 8; ++c) {
        const Eigen::Vector3d local(corner[c][0] * scene.body_sizes[i].x() / 2,
                                    corner[c][1] * scene.body_sizes[i].y() / 2,
                                    corner[c][2] * scene.body_sizes[i].z() / 2);
        const Eigen::Vector3d p = b.position + b.orientation * local;
        for (int k = 0; k < 3; ++k) vtk.points.push_back(p[k]);
        vtk.connectivity.push_back((int)(8 * i + c));
        speed.values.push_back(b.velocity.norm());
      }
    }
  }
  vtk.point_fields.push_back(speed);
  return physics::write_vtu(path, vtk);
}

// With the work split over ranks (physics::ArticulatedWorkSplit) each rank's bodies outside its active set
// are stale: gather the state of every body from the rank that counts it (a sum in which the others add
// zeros), for output and the final summary.
static PetscErrorCode SyncScene(MPI_Comm comm, const physics::ArticulatedWorkSplit &split,
                                physics::ArticulatedScene &scene)
{
  PetscFunctionBegin;
  if (split.body_counted.empty()) PetscFunctionReturn(0);
  constexpr int       nv = 13;
  std::vector<double> state(nv * scene.bodies.size(), 0.0);
  for (size_t i = 0; i < scene.bodies.size(); ++i) {
    if (!split.body_counted[i]) continue;
    const physics::RigidBody &b = scene.bodies[i];
    double                   *v = &state[nv * i];
    for (int k = 0; k < 3; ++k)
      v[k] = b.position[k], v[7 + k] = b.velocity[k], v[10 + k] = b.angular_velocity[k];
    for (int k = 0; k < 4; ++k) v[3 + k] = b.orientation.coeffs()[k];
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, state.data(), (int)state.size(), MPI_DOUBLE, MPI_SUM, comm));
  for (size_t i = 0; i < scene.bodies.size(); ++i) {
    physics::RigidBody &b = scene.bodies[i];
    const double       *v = &state[nv * i];
    for (int k = 0; k < 3; ++k)
      b.position[k] = v[k], b.velocity[k] = v[7 + k], b.angular_velocity[k] = v[10 + k];
    for (int k = 0; k < 4; ++k) b.orientation.coeffs()[k] = v[3 + k];
  }
  PetscFunctionReturn(0);
}

// Total energy and whether every body this rank moves is finite, over all ranks.
static PetscErrorCode SceneState(MPI_Comm comm, const physics::ArticulatedWorkSplit &split,
                                 const physics::ArticulatedScene &scene, double *energy, bool *finite)
{
  PetscFunctionBegin;
  double e = 0, bad = 0;
  for (size_t i = 0; i < scene.bodies.size(); ++i) {
    const physics::RigidBody &b = scene.bodies[i];
    if (!split.body_active.empty() && !split.body_active[i]) continue;
    bad += !(b.position.allFinite() && b.velocity.allFinite() && b.angular_velocity.allFinite());
    if (split.body_counted.empty() || split.body_counted[i])
      e += physics::mechanical_energy(b, scene.gravity);
  }
  if (!split.body_counted.empty()) {
    double v[2] = {e, bad};
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, v, 2, MPI_DOUBLE, MPI_SUM, comm));
    e = v[0], bad = v[1];
  }
  *energy = e, *finite = bad == 0;
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, nullptr, nullptr));
  PetscCall(PetscBinBCSRRegisterAll());
  MPI_Comm comm = PETSC_COMM_WORLD;
  int      rank, size;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));

  std::string               scene_name;
  physics::ArticulatedScene scene;
  PetscCall(BuildScene(comm, scene_name, scene));

  physics::ArticulatedParams params;
  DriverOutput               out;
  PetscInt                   max_corr = params.max_corrections, max_halvings = params.max_halvings;
  PetscBool vel_stab = PETSC_TRUE, refresh = PETSC_TRUE, warm = PETSC_FALSE, vtk_points = PETSC_FALSE;
  PetscCall(DriverOutputFromOptions(comm, &out));
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-dt", &params.dt, nullptr));
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-joint_tol", &params.joint_tol, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-max_corrections", &max_corr, nullptr));
  params.max_corrections = (int)max_corr;
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-joint_max_halvings", &max_halvings, nullptr));
  params.max_halvings = (int)max_halvings;
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-joint_regularisation", &params.regularisation, nullptr));
  PetscCall(PetscOptionsGetBool(nullptr, nullptr, "-joint_refresh", &refresh, nullptr));
  PetscCall(PetscOptionsGetBool(nullptr, nullptr, "-velocity_stabilisation", &vel_stab, nullptr));
  PetscCall(PetscOptionsGetBool(nullptr, nullptr, "-joint_warm_start", &warm, nullptr));
  params.warm_start             = warm;
  params.refresh_matrix         = refresh;
  params.velocity_stabilisation = vel_stab;
  PetscCall(PetscOptionsGetBool(nullptr, nullptr, "-vtk_points", &vtk_points, nullptr));
  const std::string bad = physics::validate_params(params);
  PetscCheck(bad.empty(), comm, PETSC_ERR_ARG_OUTOFRANGE, "%s (-dt %g, -joint_tol %g, -max_corrections %d)",
             bad.c_str(), (double)params.dt, (double)params.joint_tol, params.max_corrections);
  PetscCheck(!scene.joints.empty(), comm, PETSC_ERR_ARG_WRONG, "scene %s has no joints: nothing to solve",
             scene_name.c_str());

  physics::ArticulatedSolver solver = physics::make_articulated_solver(scene, params);
  const size_t               loops  = physics::loop_closing_joints(scene).size();
  ReplicatedSolver           rs;
  PetscCall(ReplicatedSolverCreate(comm, solver.pattern.n_joints, solver.pattern.block_row,
                                   solver.pattern.block_col, &rs));
  const physics::BlockLinearSolver linear = ReplicatedSolverAdapter(&rs);
  if (params.warm_start)
    PetscCall(KSPSetInitialGuessNonzero(rs.sys.ksp, PETSC_TRUE)); // the physics supplies the guesses
  if (size > 1) { // each rank moves the bodies of its own joints only; the error maxima are all-reduced
    std::vector<int> joint_rank(scene.joints.size());
    for (int p = 0; p < size; ++p)
      for (int i = rs.row_offsets[p]; i < rs.row_offsets[p + 1]; ++i) joint_rank[rs.old_of_new[i]] = p;
    solver.split                    = physics::split_articulated_work(scene, joint_rank, rank);
    solver.split.max_over_processes = [&rs](double local) {
      double global = local;
      if (MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MAX, rs.comm) != MPI_SUCCESS && !rs.error)
        rs.error = PETSC_ERR_MPI;
      return global;
    };
  }
  PetscInt    nnz;
  const char *mat_type, *ksp_type;
  PetscCall(BlockSystemGetInfo(&rs.sys, &nnz, &mat_type, &ksp_type));
  PetscCall(PetscPrintf(comm,
                        "articulated: scene %s, %zu bodies, %zu joints (%zu rows), %zu loops, %" PetscInt_FMT
                        " nonzeros, mat %s, ksp %s, %d ranks\n",
                        scene_name.c_str(), scene.bodies.size(), scene.joints.size(), 3 * scene.joints.size(),
                        loops, nnz, mat_type, ksp_type, size));

  auto write_frame = [&](PetscInt n) {
    return DriverWriteFrame(comm, &out, n, n * params.dt,
                            [&](const std::string &path) { return WriteFrame(path, scene, vtk_points); });
  };
  PetscCall(write_frame(0));

  double e0;
  bool   finite0;
  PetscCall(SceneState(comm, solver.split, scene, &e0, &finite0));
  RunGuard guard;
  {
    // The scene's energy scale: its weight over its extent, plus the kinetic energy it starts with.
    double          m = 0, ke0 = 0;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (size_t i = 0; i < scene.bodies.size(); ++i) {
      const physics::RigidBody &b = scene.bodies[i];
      m += b.mass;
      ke0 += physics::mechanical_energy(b, Eigen::Vector3d::Zero());
      const double r = 0.5 * scene.body_sizes[i].norm();
      lo             = lo.cwiseMin(b.position - Eigen::Vector3d::Constant(r));
      hi             = hi.cwiseMax(b.position + Eigen::Vector3d::Constant(r));
    }
    HealthBounds hb;
    hb.energy_scale  = m * scene.gravity.norm() * (hi - lo).norm() + ke0;
    hb.energy_growth = 0.1;
    // A joint still open by 5% of the smallest body after a step is an articulation that came
    // apart (a step far too long, masses the projection cannot balance), not a tolerance missed.
    double smallest = INFINITY;
    for (const Eigen::Vector3d &size : scene.body_sizes) smallest = std::min(smallest, size.norm());
    hb.joint_error = std::isfinite(smallest) && smallest > 0 ? 0.05 * smallest : NAN;
    PetscCall(RunGuardFromOptions(comm, hb, &guard));
    RunGuardStart(&guard, e0, NAN);
  }
  double    e_max = e0, worst_error = 0, worst_velocity = 0;
  long long done = 0, corrections = 0, halvings = 0, max_corrections_seen = 0, unconverged = 0, stalled = 0,
            singular_steps = 0, nan_steps = 0;
  StepCosts costs;
  for (PetscInt n = 1; n <= out.steps; ++n) {
    const long long its0 = rs.iterations, solves0 = rs.solves, diverged0 = rs.diverged_solves;
    const double    solve0 = rs.solve_ms, t0 = WallTime();
    const physics::ArticulatedStepReport r       = physics::articulated_step(scene, solver, params, linear);
    const double                         step_ms = 1e3 * (WallTime() - t0);
    PetscCall(rs.error);
    ++done;
    costs.add(step_ms, rs.iterations - its0, rs.solves - solves0);
    double energy;
    bool   finite;
    PetscCall(SceneState(comm, solver.split, scene, &energy, &finite));
    nan_steps += !finite;
    corrections += r.corrections;
    halvings += r.halvings;
    max_corrections_seen = std::max<long long>(max_corrections_seen, r.corrections);
    unconverged += !r.converged;
    stalled += r.stalled;
    singular_steps += r.singular_detected;
    worst_error    = std::max(worst_error, r.joint_error);
    worst_velocity = std::max(worst_velocity, r.velocity_error);
    e_max          = std::max(e_max, energy);
    if (n % out.progress_every == 0 || n == out.steps)
      PetscCall(PetscPrintf(
        comm,
        "step %" PetscInt_FMT
        " t=%.6g corrections=%d solves=%lld cg_its=%lld joint_err=%.3e vel_err=%.3e energy=%.6e ms=%.2f solve_ms=%.2f%s%s\n",
        n, n * params.dt, r.corrections, rs.solves - solves0, rs.iterations - its0, r.joint_error,
        r.velocity_error, energy, step_ms, rs.solve_ms - solve0, r.converged ? "" : " UNCONVERGED",
        r.singular_detected ? " SINGULAR->regularised" : ""));
    if (n == 1 && out.dump) PetscCall(BlockSystemDumpMatrix(&rs.sys, out.dump_path));
    if (out.vtk && n % out.vtk_every == 0) PetscCall(SyncScene(comm, solver.split, scene));
    PetscCall(write_frame(n));
    StepHealth health;
    // A breakdown that switched the step to the regularised matrix, or a warm start solved again from
    // zero, is the physics' own recovery; any other failed solve leaves the impulses it produced (or
    // zeros) in the step.
    if (rs.diverged_solves - diverged0 > r.recovered_solves) {
      health.solver_reason = rs.worst_reason;
      health.solver_detail = rs.worst_detail;
    }
    health.energy      = energy;
    health.joint_error = r.joint_error;
    health.finite      = finite && std::isfinite(energy);
    bool stop;
    PetscCall(RunGuardCheckStep(comm, &guard, n, health, &stop));
    if (stop) break;
  }
  PetscCall(SyncScene(comm, solver.split, scene)); // every body's state on every rank for the summary

  SummaryLine s;
  s.add("program", std::string("articulated"));
  s.add("scene", scene_name);
  s.add("ranks", (long long)size);
  s.add("bodies", (long long)scene.bodies.size());
  s.add("joints", (long long)scene.joints.size());
  s.add("rows", (long long)(3 * scene.joints.size()));
  s.add("nnz", (long long)nnz);
  s.add("loops", (long long)loops);
  s.add("mat_type", std::string(mat_type));
  s.add("ksp_type", std::string(ksp_type));
  s.add("steps", done);
  s.add("dt", params.dt);
  DriverAddSolverSummary(s, rs, costs);
  s.add("solves", rs.solves);
  s.add("cg_its_per_step", done ? (double)rs.iterations / done : 0.0);
  s.add("corrections_per_step", done ? (double)corrections / done : 0.0);
  s.add("corrections_max", max_corrections_seen);
  s.add("halvings_per_step", done ? (double)halvings / done : 0.0);
  s.add("unconverged_steps", unconverged);
  s.add("stalled_steps", stalled);
  s.add("regularised", (long long)solver.regularised);
  s.add("singular_detections", singular_steps);
  s.add("joint_error_max", worst_error);
  s.add("joint_error_final", physics::max_joint_error(scene));
  s.add("velocity_error_max", worst_velocity);
  s.add("energy_initial", e0);
  s.add("energy_final", physics::total_energy(scene));
  s.add("energy_growth_max", e_max - e0);
  s.add("nan", nan_steps);
  {
    std::vector<double> xyz;
    for (const physics::RigidBody &b : scene.bodies)
      xyz.insert(xyz.end(), {b.position[0], b.position[1], b.position[2]});
    PetscCall(DriverComparePositions(comm, xyz, s));
  }
  RunGuardAddSummary(s, guard);
  PetscCall(PrintSummary(comm, s));

  PetscCall(ReplicatedSolverDestroy(&rs));
  PetscCall(PetscFinalize());
  return guard.exit_code;
}
