// Implicit cloth (physics/cloth_step.hpp): an n x n particle grid, one 3x3-block system per step refilled in
// place and solved through PETSc with the configured -mat_type/-ksp_type/-pc_type; -pc_type mg is a geometric
// multigrid on the particle grid (sim/grid_mg.h).
//
//   cloth -options_file options/cloth.opts [-cloth_n 160] [-steps N] [-mat_type binbcsr] [-ksp_type mcg]
//
// Scene: -cloth_n, -cloth_size (m), -cloth_mass (kg), -cloth_k_stretch, -cloth_k_shear, -cloth_k_bend (N/m),
// -cloth_damping (N s/m), -cloth_pins corners|four|top|none, -cloth_hanging, -sphere (drape over a sphere;
// -sphere_radius, -sphere_centre x,y,z), -cloth_strain_limit S (stretch springs kept within (1 + S) x rest
// length, Provot; 0: off), -cloth_strain_limit_sweeps N and -cloth_strain_limit_omega W (its sweeps
// over-relaxed, W in [1, 2)). Time: -dt, -steps, -cloth_exact_jacobian (drop Choi-Ko). Output: a progress
// line every -progress_every steps, -vtk PREFIX (triangle surface per -vtk_every steps),
// -dump_matrix FILE (first step's matrix), -write_positions / -reference_positions FILE (rms and largest
// position difference against another run, sim/position_file.h), and a final `summary key=value ...` line;
// -cloth_timer cpu times in process CPU time instead of wall time (a shared machine). More ranks:
// -rows_partition metis|contiguous (with -pc_type mg contiguous by default: strips of the grid).
#include "sim/run_guard.h"
#include "sim/grid_mg.h"
#include "sim/position_file.h"
#include "sim/sim_driver.h"
#include "physics/cloth_step.hpp"
#include "physics/vtk_writer.hpp"

#include <petscbinbcsr.h>

#include <cmath>
#include <cstring>

static bool WriteFrame(const std::string &path, const physics::Cloth &cloth)
{
  physics::VtkScene vtk;
  vtk.cell_type      = physics::VtkCellType::Triangle;
  vtk.nodes_per_cell = 3;
  physics::VtkPointField speed{"speed", 1, {}}, pinned{"pinned", 1, {}};
  for (int p = 0; p < cloth.particle_count(); ++p) {
    for (int k = 0; k < 3; ++k) vtk.points.push_back(cloth.position[p][k]);
    speed.values.push_back(cloth.velocity[p].norm());
    pinned.values.push_back(cloth.fixed[p]);
  }
  const int n = cloth.n;
  for (int i = 0; i + 1 < n; ++i)
    for (int j = 0; j + 1 < n; ++j) {
      const int a = i * n + j, b = a + 1, c = a + n, d = c + 1;
      vtk.connectivity.insert(vtk.connectivity.end(), {a, b, d, a, d, c});
    }
  vtk.point_fields = {speed, pinned};
  return physics::write_vtu(path, vtk);
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, nullptr, nullptr));
  PetscCall(PetscBinBCSRRegisterAll());
  MPI_Comm comm = PETSC_COMM_WORLD;
  int      rank, size;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));

  physics::ClothOptions opt;
  PetscInt              n         = opt.n;
  bool                  cpu_timer = false;
  PetscBool             hanging = PETSC_FALSE, sphere = PETSC_FALSE, exact = PETSC_FALSE, set;
  char                  pins[32] = "corners";
  DriverOutput          out;
  PetscReal             radius = 0.3, centre[4] = {0, -0.5, 0}; // one place more: a fourth number is seen
  PetscInt              ncentre = 4;
  physics::ClothParams  params;
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-cloth_n", &n, nullptr));
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-cloth_size", &opt.size, nullptr));
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-cloth_mass", &opt.total_mass, nullptr));
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-cloth_k_stretch", &opt.k_stretch, nullptr));
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-cloth_k_shear", &opt.k_shear, nullptr));
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-cloth_k_bend", &opt.k_bend, nullptr));
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-cloth_damping", &opt.damping, nullptr));
  PetscCall(PetscOptionsGetBool(nullptr, nullptr, "-cloth_hanging", &hanging, nullptr));
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-cloth_pins", pins, sizeof pins, nullptr));
  PetscCall(PetscOptionsGetBool(nullptr, nullptr, "-sphere", &sphere, nullptr));
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-sphere_radius", &radius, nullptr));
  PetscCall(PetscOptionsGetRealArray(nullptr, nullptr, "-sphere_centre", centre, &ncentre, &set));
  PetscCheck(!set || ncentre == 3, comm, PETSC_ERR_ARG_SIZ,
             "-sphere_centre needs 3 numbers, got %" PetscInt_FMT, ncentre);
  PetscCall(PetscOptionsGetBool(nullptr, nullptr, "-cloth_exact_jacobian", &exact, nullptr));
  {
    PetscInt sweeps = params.strain_limit.max_sweeps;
    PetscCall(
      PetscOptionsGetReal(nullptr, nullptr, "-cloth_strain_limit", &params.strain_limit.max_strain, nullptr));
    PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-cloth_strain_limit_sweeps", &sweeps, nullptr));
    PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-cloth_strain_limit_omega", &params.strain_limit.omega,
                                  nullptr));
    params.strain_limit.max_sweeps = (int)sweeps;
  }
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-dt", &params.dt, nullptr));
  {
    const char *timers[] = {"wall", "cpu"};
    PetscInt    t        = 0;
    PetscCall(PetscOptionsGetEList(nullptr, nullptr, "-cloth_timer", timers, 2, &t, nullptr));
    cpu_timer = t == 1;
  }
  params.clock = cpu_timer ? ProcessCpuTime : WallTime; // the strain limiting's share of physics_ms
  PetscCall(DriverOutputFromOptions(comm, &out));
  params.choi_ko = !exact;
  opt.n          = (int)n;
  opt.hanging    = hanging;
  if (!std::strcmp(pins, "corners")) opt.pins = physics::ClothPins::TwoCorners;
  else if (!std::strcmp(pins, "four")) opt.pins = physics::ClothPins::FourCorners;
  else if (!std::strcmp(pins, "top")) opt.pins = physics::ClothPins::TopRow;
  else if (!std::strcmp(pins, "none")) opt.pins = physics::ClothPins::None;
  else SETERRQ(comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "unknown -cloth_pins %s (corners, four, top, none)", pins);
  const std::string bad = physics::validate_params(params);
  PetscCheck(
    bad.empty(), comm, PETSC_ERR_ARG_OUTOFRANGE,
    "%s (-dt %g, -cloth_strain_limit %g, -cloth_strain_limit_sweeps %d, -cloth_strain_limit_omega %g)",
    bad.c_str(), (double)params.dt, (double)params.strain_limit.max_strain, params.strain_limit.max_sweeps,
    (double)params.strain_limit.omega);
  PetscCheck(!sphere || radius > 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "-sphere_radius must be positive, got %g",
             (double)radius);
  // the springs' squared lengths must stay finite: past this make_cloth refused "spring 0", which named
  // no option
  PetscCheck(opt.size > 0 && opt.size <= 1e100, comm, PETSC_ERR_ARG_OUTOFRANGE,
             "-cloth_size must be positive and at most 1e100 m, got %g", (double)opt.size);

  // The matrix holds about 13 blocks of 9 entries per particle, and PETSc's indices here are 32-bit:
  // past that n the allocation failed (std::bad_alloc) or the counts overflowed.
  PetscCheck((long long)n * n * 117 <= (long long)PETSC_MAX_INT, comm, PETSC_ERR_ARG_OUTOFRANGE,
             "-cloth_n %" PetscInt_FMT ": the system's %lld entries exceed PETSc's index range (%d)", n,
             (long long)n * n * 117, PETSC_MAX_INT);

  physics::Cloth cloth;
  try {
    cloth = physics::make_cloth(opt);
  } catch (const std::invalid_argument &e) {
    SETERRQ(comm, PETSC_ERR_ARG_OUTOFRANGE, "cloth: %s", e.what());
  } catch (const std::bad_alloc &) {
    SETERRQ(comm, PETSC_ERR_MEM, "cloth: not enough memory for a %" PetscInt_FMT " x %" PetscInt_FMT " cloth",
            n, n);
  }
  cloth.sphere.enabled      = sphere;
  cloth.sphere.radius       = radius;
  cloth.sphere.centre       = Eigen::Vector3d(centre[0], centre[1], centre[2]);
  const std::string problem = physics::validate_cloth(cloth);
  PetscCheck(problem.empty(), comm, PETSC_ERR_ARG_WRONG, "cloth: %s", problem.c_str());

  // Each rank assembles only its own rows, and of their blocks only those its Mat type stores.
  ReplicatedSolver     rs;
  physics::ClothSystem sys;
  rs.cpu_timer = cpu_timer;
  {
    // The grid multigrid coarsens whole grid rows and sweeps slabs of them: with -pc_type mg the ranks
    // get strips of the row-major grid (cloth.opts, 2 ranks: 133-139 -> 118-119 ms per step against
    // METIS's jagged cut, docs/cloth.md); -rows_partition metis|contiguous chooses.
    char pc_type[64] = "";
    PetscCall(PetscOptionsGetString(nullptr, nullptr, "-pc_type", pc_type, sizeof pc_type, nullptr));
    rs.contiguous_parts = !std::strcmp(pc_type, "mg");
  }
  {
    const physics::ClothSystem all = physics::make_cloth_system(cloth);
    PetscCall(ReplicatedSolverNumber(comm, all.n_particles, all.block_row, all.block_col, &rs));
  }
  {
    std::vector<char> own(cloth.particle_count());
    for (int p = 0; p < cloth.particle_count(); ++p) own[p] = ReplicatedSolverOwnsRow(&rs, p);
    sys = physics::make_cloth_system(
      cloth, own, [&](int row, int col) { return ReplicatedSolverStoresBlock(&rs, row, col); });
  }
  PetscCall(ReplicatedSolverSetLocalPattern(&rs, sys.block_row, sys.block_col));
  // -pc_type mg: geometric multigrid on the particle grid (sim/grid_mg.h); PCMG alone knows no levels.
  physics::BlockLinearSolver linear = ReplicatedSolverAdapter(&rs);
  GridMG                     mg;
  PetscBool                  is_mg;
  {
    PC pc;
    PetscCall(KSPGetPC(rs.sys.ksp, &pc));
    PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCMG, &is_mg));
  }
  if (is_mg) {
    PetscCall(GridMGSetUp(rs.sys.ksp, cloth.n, cloth.fixed, rs.new_of_old, rs.row_offsets, sys.block_row,
                          sys.block_col, rs.upper_only, rs.offrank_full, &mg));
    PetscCall(PetscPrintf(comm, "cloth: grid multigrid, %zu level(s):", mg.sides.size()));
    for (PetscInt side : mg.sides) PetscCall(PetscPrintf(comm, " %" PetscInt_FMT "^2", side));
    PetscCall(
      PetscPrintf(comm, " nodes, coarse operators by %s, smoothers on %s, %s\n",
                  mg.distributed ? "blocks (each rank's share)" : (mg.own_galerkin ? "blocks" : "MatPtAP"),
                  mg.single_smoothers ? "single-precision copies" : "the operators",
                  !mg.smoother_slab ? "SOR sweeps"
                  : size == 1       ? "slab Gauss-Seidel sweeps where the couplings allow"
                              : "slab Gauss-Seidel sweeps on each rank's rows where the couplings allow"));
    // The coarse operators follow every refill of the fine matrix (timed with it: setvalues_ms).
    linear.set_matrix = [&rs, &mg, fine = linear.set_matrix](const std::vector<double> &values) {
      fine(values);
      const auto   now = rs.cpu_timer ? ProcessCpuTime : WallTime;
      const double t0  = now();
      if (!rs.error) rs.error = GridMGRefill(&mg, values.data());
      rs.setvalues_ms += 1e3 * (now() - t0);
    };
  }
  PetscInt    nnz;
  const char *mat_type, *ksp_type;
  PetscCall(BlockSystemGetInfo(&rs.sys, &nnz, &mat_type, &ksp_type));
  PetscCall(PetscPrintf(comm,
                        "cloth: %d x %d particles (%d unknowns), %zu springs, %" PetscInt_FMT
                        " nonzeros, mat %s, ksp %s, %d ranks\n",
                        cloth.n, cloth.n, 3 * cloth.particle_count(), cloth.springs.size(), nnz, mat_type,
                        ksp_type, size));
  PetscCall(PetscSynchronizedPrintf(comm, "  rank %d assembles %zu springs, %zu blocks\n", rank,
                                    sys.springs.size(), sys.block_row.size()));
  PetscCall(PetscSynchronizedFlush(comm, PETSC_STDOUT));

  auto write_frame = [&](PetscInt step) {
    return DriverWriteFrame(comm, &out, step, step * params.dt,
                            [&](const std::string &path) { return WriteFrame(path, cloth); });
  };
  PetscCall(write_frame(0));

  const double e0 = physics::cloth_energy(cloth);
  RunGuard     guard;
  {
    // The scene's energy scale: its weight over its size, plus the kinetic energy it starts with. The
    // sphere's contact projection adds spring energy (7 J, 1.5 x the scale, for 20 x 20 particles
    // draped for 20 steps), so the bound is 4 x the scale; a spring at twice its rest length is no
    // cloth any more.
    double m = 0, ke0 = 0;
    for (int p = 0; p < cloth.particle_count(); ++p)
      m += cloth.mass[p], ke0 += 0.5 * cloth.mass[p] * cloth.velocity[p].squaredNorm();
    HealthBounds hb;
    hb.energy_scale  = m * cloth.gravity.norm() * opt.size + ke0;
    hb.energy_growth = 4.0;
    hb.max_stretch   = 2.0;
    PetscCall(RunGuardFromOptions(comm, hb, &guard));
    RunGuardStart(&guard, e0, NAN);
  }
  const auto now         = cpu_timer ? ProcessCpuTime : WallTime;
  double     max_stretch = 0;
  long long  nan_steps = 0, unconverged = 0, contacts = 0, done = 0, limit_sweeps = 0, limit_capped = 0;
  double     limit_s = 0;
  StepCosts  costs;
  for (PetscInt step = 1; step <= out.steps; ++step) {
    const long long                its0 = rs.iterations, solves0 = rs.solves;
    const double                   solve0 = rs.solve_ms, t0 = now();
    const physics::ClothStepReport r       = physics::cloth_step(cloth, sys, params, linear);
    const double                   step_ms = 1e3 * (now() - t0);
    PetscCall(rs.error);
    ++done;
    costs.add(step_ms, rs.iterations - its0, rs.solves - solves0);
    bool finite = true;
    for (int p = 0; p < cloth.particle_count(); ++p)
      finite &= cloth.position[p].allFinite() && cloth.velocity[p].allFinite();
    nan_steps += !finite;
    unconverged += !r.converged;
    contacts += r.contacts;
    limit_sweeps += r.strain_sweeps;
    limit_capped += r.strain_capped;
    limit_s += r.strain_seconds;
    max_stretch = std::max(max_stretch, r.max_stretch); // this rank's springs: reduced where printed
    if (step % out.progress_every == 0 || step == out.steps) {
      double stretch = r.max_stretch;
      PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &stretch, 1, MPI_DOUBLE, MPI_MAX, comm));
      PetscCall(PetscPrintf(
        comm,
        "step %" PetscInt_FMT
        " t=%.6g cg_its=%lld stretch=%.5f contacts=%d energy=%.6e ms=%.2f solve_ms=%.2f%s\n",
        step, step * params.dt, rs.iterations - its0, stretch, r.contacts, physics::cloth_energy(cloth),
        step_ms, rs.solve_ms - solve0, r.converged ? "" : " UNCONVERGED"));
    }
    if (step == 1 && out.dump) PetscCall(BlockSystemDumpMatrix(&rs.sys, out.dump_path));
    PetscCall(write_frame(step));
    StepHealth health;
    health.solver_reason = rs.last.reason;
    health.solver_detail = rs.last.pc_failure;
    health.energy        = physics::cloth_energy(cloth);
    health.finite        = finite && std::isfinite(health.energy);
    health.max_stretch   = r.max_stretch;
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &health.max_stretch, 1, MPI_DOUBLE, MPI_MAX, comm));
    bool stop;
    PetscCall(RunGuardCheckStep(comm, &guard, step, health, &stop));
    if (stop) break;
  }

  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &max_stretch, 1, MPI_DOUBLE, MPI_MAX, comm));
  double ke = 0;
  for (int p = 0; p < cloth.particle_count(); ++p)
    ke += 0.5 * cloth.mass[p] * cloth.velocity[p].squaredNorm();
  SummaryLine s;
  s.add("program", std::string("cloth"));
  s.add("ranks", (long long)size);
  s.add("n", (long long)cloth.n);
  s.add("unknowns", (long long)(3 * cloth.particle_count()));
  s.add("springs", (long long)cloth.springs.size());
  s.add("nnz", (long long)nnz);
  s.add("mat_type", std::string(mat_type));
  s.add("ksp_type", std::string(ksp_type));
  s.add("steps", (long long)done);
  s.add("dt", params.dt);
  DriverAddSolverSummary(s, rs, costs);
  s.add("steps_per_s", costs.total_ms() > 0 ? 1e3 * done / costs.total_ms() : 0.0);
  s.add("unconverged_steps", unconverged);
  s.add("max_stretch", max_stretch);
  // the strain limiting (every rank limits the whole replicated cloth): its time per step (part of
  // physics_ms), sweeps per step, and the steps whose sweeps ran out while the last one still corrected
  // springs (then max_stretch may exceed 1 + -cloth_strain_limit)
  s.add("limit_ms", done ? 1e3 * limit_s / done : 0.0);
  s.add("limit_sweeps", done ? (double)limit_sweeps / done : 0.0);
  s.add("limit_capped_steps", limit_capped);
  s.add("contacts", contacts);
  s.add("energy_initial", e0);
  s.add("energy_final", physics::cloth_energy(cloth));
  s.add("kinetic_final", ke);
  s.add("nan", nan_steps);
  {
    std::vector<double> xyz;
    for (const Eigen::Vector3d &x : cloth.position) xyz.insert(xyz.end(), {x[0], x[1], x[2]});
    PetscCall(DriverComparePositions(comm, xyz, s));
  }
  RunGuardAddSummary(s, guard);
  PetscCall(PrintSummary(comm, s));

  PetscCall(GridMGDestroy(&mg));
  PetscCall(ReplicatedSolverDestroy(&rs));
  PetscCall(PetscFinalize());
  return guard.exit_code;
}
