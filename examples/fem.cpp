// Corotational FEM driver: linear or quadratic tetrahedra, implicit Euler, one linear solve per step
// on a fixed-pattern 3x3-block matrix refilled in place (any -mat_type, any -ksp_type).
//
//   fem -mesh_box 1,0.1,0.1,20,2,2 -fem_order 2 -fix xmin -steps 50 -mat_type binbcsr -ksp_type mcg
//   fem -mesh examples/meshes/armadillo.geo -mesh_size 0.08 -fem_order 2 -vtk out/arma
//   -write_positions / -reference_positions FILE: the final positions, in the input's node order, written
//   or compared (rms and largest distance in the summary; src/sim/position_file.h)
//
// Parallel runs (mpiexec -n P): every rank holds the whole mesh and state; METIS splits the nodes
// into P contiguous ranges (src/physics/partition), each rank assembles the elements inside its range
// and a balancing share of the cut ones (COO entries may fall in other ranks' rows), the solve is
// distributed, and dv is
// gathered back to every rank.
//
// Fixed nodes are eliminated: their rows and columns hold only an identity diagonal block and their
// right-hand side is 0, so dv = 0 there, the matrix stays SPD and the pattern never changes.
#include <petscbinbcsr.h>

#include "sim/fem_health.h"
#include "sim/fem_options.h"
#include "sim/fem_simulation.h"
#include "sim/geo_mesh.h"
#include "sim/position_file.h"
#include "sim/summary.h"
#include "physics/box_mesh.hpp"
#include "physics/corotational_assembly.hpp"
#include "physics/element_batch.hpp"
#include "physics/fem_model.hpp"
#include "physics/msh_reader.hpp"
#include "physics/tet_mesh.hpp"
#include "physics/vtk_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

static const char help[] = "Corotational FEM (P1/P2 tetrahedra), implicit Euler, matrix refilled in place.\n"
                           "See docs/fem.md for every option.\n";

int main(int argc, char **argv)
{
  FemOptions  o;
  PetscMPIInt rank, size;

  PetscCall(PetscInitialize(&argc, &argv, nullptr, help));
  PetscCall(PetscBinBCSRRegisterAll());
  MPI_Comm comm = PETSC_COMM_WORLD;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(FemGetOptions(o));

  // ---- scene: mesh, fixed nodes, material; FemSimulation renumbers and builds the system -------
  FemScene    scene;
  std::string mesh_name;
  {
    std::string msh = o.mesh;
    if (msh.size() > 4 && msh.substr(msh.size() - 4) == ".geo")
      PetscCall(GeoMesh(comm, msh, o.mesh_size, o.mesh_max_elements, &msh));
    std::string error;
    try {
      if (!msh.empty()) {
        scene.mesh = physics::read_msh_file(msh);
        mesh_name  = o.mesh;
      } else {
        scene.mesh =
          physics::make_box_mesh(o.box[0], o.box[1], o.box[2], (int)o.box[3], (int)o.box[4], (int)o.box[5]);
        mesh_name = "box";
      }
      if (o.order == 2) scene.mesh = physics::promote_to_quadratic(scene.mesh);
      scene.fixed = FemSelectFixed(scene.mesh, o);
    } catch (const std::exception &ex) {
      error = ex.what();
    }
    PetscCheck(error.empty(), comm, PETSC_ERR_USER_INPUT, "%s", error.c_str());
    // a free body has no static equilibrium under gravity: its stiffness matrix is singular (the rigid
    // motions), and the Newton solve diverged (DIVERGED_DTOL) without saying why
    PetscCheck(!o.is_static || std::count(scene.fixed.begin(), scene.fixed.end(), 1) > 0, comm,
               PETSC_ERR_USER_INPUT,
               "-static needs fixed nodes (-fix or -fix_box): a free body has no equilibrium and a singular "
               "stiffness matrix");
    scene.settings.young        = o.young;
    scene.settings.poisson      = o.poisson;
    scene.settings.density      = o.density;
    scene.settings.corotational = o.corotational;
    scene.settings.mass         = o.lumped ? physics::MassLumping::Lumped : physics::MassLumping::Consistent;
    scene.gravity               = {o.gravity[0], o.gravity[1], o.gravity[2]};
    scene.dt                    = o.dt;
    scene.rayleigh_alpha        = o.rayleigh[0];
    scene.rayleigh_beta         = o.rayleigh[1];
    scene.is_static             = o.is_static;
    scene.merge_blocks          = o.merge;
    scene.rigid_body_modes      = o.rigid_body_modes;
    scene.reorder               = o.reorder;
    scene.bin_order_window      = (int)o.bin_order_window;
  }
  const int     tip_input = FemTipNode(scene.mesh, scene.fixed);
  FemSimulation sim;
  PetscCall(FemSimulationCreate(comm, scene, &sim));
  sim.cpu_timer      = o.cpu_timer;
  sim.element_kernel = o.scalar_elements ? physics::ElementKernel::Scalar : physics::ElementKernel::Batched;
  sim.element_body   = (binbcsr::BodySet)o.element_body;
  sim.guess_order    = o.guess_order == 3 ? 0 : (int)o.guess_order;
  if (o.guess_order == 3) {
    // Projection: each solve starts from the combination of the window's solutions whose right-hand
    // sides best match the new one (least squares, pseudoinverse; PETSc's KSPGuess Fischer model 3). It
    // replaces the extrapolation: on linear_38k (GAMG, rtol 1e-6) 24.2 -> 19.6 CG iterations per step
    // with plain aggregation, 14.2 -> 11.5 with smoothed (docs/fem.md); with pbjacobi it was worse
    // than extrapolating (243 -> 338), so it is a choice, not the default.
    KSPGuess g;
    PetscCall(KSPGetGuess(sim.sys.ksp, &g));
    PetscCall(KSPGuessSetType(g, KSPGUESSFISCHER));
    PetscCall(KSPGuessFischerSetModel(g, 3, o.guess_window));
  }
  const physics::FemModel   &model   = sim.model;
  const int                  n_nodes = model.node_count(), npe = model.npe, tip = sim.new_of_old[tip_input];
  const std::vector<double> &X = model.mesh.nodes;
  std::vector<double>       &x = sim.x, &v = sim.v;

  // ---- initial state ------------------------------------------------------------------------
  {
    double c[3] = {0, 0, 0};
    for (int i = 0; i < n_nodes; ++i)
      for (int d = 0; d < 3; ++d) c[d] += X[3 * i + d] / n_nodes;
    for (int i = 0; i < n_nodes; ++i) {
      if (sim.fixed[i]) continue;
      const double r[3] = {X[3 * i] - c[0], X[3 * i + 1] - c[1], X[3 * i + 2] - c[2]};
      for (int d = 0; d < 3; ++d) x[3 * i + d] = c[d] + o.stretch * r[d];
      v[3 * i + 0] = o.v0[0] + o.spin[1] * r[2] - o.spin[2] * r[1];
      v[3 * i + 1] = o.v0[1] + o.spin[2] * r[0] - o.spin[0] * r[2];
      v[3 * i + 2] = o.v0[2] + o.spin[0] * r[1] - o.spin[1] * r[0];
    }
    if (o.perturb[0] >= 0) {
      // The node is named in the numbering of the input (promoted) mesh.
      PetscCheck((PetscInt)o.perturb[0] < n_nodes, comm, PETSC_ERR_ARG_OUTOFRANGE,
                 "-initial_perturb: node out of range");
      const int node = sim.new_of_old[(int)o.perturb[0]];
      for (int d = 0; d < 3; ++d) x[3 * node + d] += o.perturb[1 + d];
    }
  }

  auto min_volume_ratio = [&] {
    double r = 1e300;
    for (int e = 0; e < model.element_count(); ++e)
      r = std::min(r, physics::element_signed_volume(model.mesh, x.data(), e) / model.volume[e]);
    return r;
  };
  auto     inverted_fraction = [&] { return FemInvertedFraction(sim); };
  RunGuard guard;
  {
    // The initial state's figures from its element pass, which then serves the first step (and gives
    // the bounds the state's energy without the definition's walk over every element's K0).
    FemStepInfo start;
    PetscCall(FemSimulationAssembleState(&sim, &start));
    PetscCall(RunGuardFromOptions(comm, FemHealthBounds(sim), &guard));
    RunGuardStart(&guard, start.energy, start.inverted_fraction);
  }
  PetscInt    nnz;
  const char *mat_type, *ksp_type;
  PetscCall(BlockSystemGetInfo(&sim.sys, &nnz, &mat_type, &ksp_type));
  const long long n_fixed = std::count(sim.fixed.begin(), sim.fixed.end(), 1);
  PetscCall(PetscPrintf(
    comm,
    "fem: mesh %s order %d elements %d nodes %d dofs %d fixed nodes %lld nnz %" PetscInt_FMT
    " ranks %d mat %s ksp %s corotational %d mass %s\n",
    mesh_name.c_str(), (int)o.order, model.element_count(), n_nodes, 3 * n_nodes, n_fixed, nnz, size,
    mat_type, ksp_type, (int)o.corotational, o.order == 1 ? "lumped" : (o.lumped ? "hrz" : "consistent")));
  PetscCall(PetscPrintf(comm, "fem: initial min volume ratio %g (negative: inverted elements)\n",
                        min_volume_ratio()));

  std::vector<std::pair<std::string, double>> frames;
  auto                                        write_frame = [&](int step) {
    if (rank || !o.vtk[0]) return;
    physics::VtkScene vs;
    vs.points = x;
    vs.cell_type = npe == 4 ? physics::VtkCellType::Tetra : physics::VtkCellType::QuadraticTetra;
    vs.nodes_per_cell = npe;
    vs.connectivity   = model.mesh.elements;
    std::vector<double> u(x.size());
    for (size_t k = 0; k < x.size(); ++k) u[k] = x[k] - X[k];
    std::vector<double> fx(sim.fixed.begin(), sim.fixed.end());
    vs.point_fields = {{"displacement", 3, u}, {"velocity", 3, v}, {"fixed", 1, fx}};
    char name[PETSC_MAX_PATH_LEN];
    std::snprintf(name, sizeof name, "%s_%04d.vtu", o.vtk, step);
    if (!physics::write_vtu(name, vs)) return;
    std::string rel = name;
    rel             = rel.substr(rel.find_last_of('/') + 1);
    frames.emplace_back(rel, step * o.dt);
    physics::write_pvd(std::string(o.vtk) + ".pvd", frames);
  };
  if (!rank && o.vtk[0]) physics::make_prefix_folder(o.vtk); // failure shows up as no frames, reported below
  write_frame(0);
  PetscCheck(rank || !o.vtk[0] || !frames.empty(), PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN,
             "-vtk %s: cannot write %s_0000.vtu", o.vtk, o.vtk);

  // ---- time loop ----------------------------------------------------------------------------
  double             t_element = 0, t_setvalues = 0, t_solve = 0, t_comm = 0;
  long long          its_total = 0, svd_rotations = 0;
  int                steps_done = 0;
  StepCosts          costs;
  KSPConvergedReason last_reason = KSP_CONVERGED_ITERATING;
  for (int step = 1; step <= o.steps; ++step) {
    FemStepInfo info;
    PetscCall(FemSimulationStep(&sim, &info));
    if (step == 1 && o.dump[0]) PetscCall(BlockSystemDumpMatrix(&sim.sys, o.dump));
    // The new state's element pass: the health check's energy and inverted fraction, and the next
    // step's blocks and forces (one walk over the elements for both).
    PetscCall(FemSimulationAssembleState(&sim, &info));
    t_element += info.element_ms;
    t_comm += info.comm_ms;
    t_setvalues += info.setvalues_ms;
    t_solve += info.solve_ms;
    its_total += info.stats.iterations;
    svd_rotations += info.svd_rotations;
    last_reason = info.stats.reason;
    steps_done  = step;
    costs.add(info.total_ms, info.stats.iterations, 1);
    if (!o.quiet)
      PetscCall(PetscPrintf(
        comm, "step %d its %" PetscInt_FMT " res %.3e reason %s assembly_ms %.2f solve_ms %.2f\n", step,
        info.stats.iterations, (double)info.stats.residual_norm, KSPConvergedReasons[info.stats.reason],
        info.element_ms + info.setvalues_ms, info.solve_ms));
    StepHealth health;
    health.solver_reason     = info.stats.reason;
    health.solver_detail     = info.stats.pc_failure;
    health.energy            = info.energy;
    health.finite            = info.finite && std::isfinite(health.energy);
    health.inverted_fraction = info.inverted_fraction;
    bool stop;
    PetscCall(RunGuardCheckStep(comm, &guard, step, health, &stop));
    if (stop) break;
    if (step % o.vtk_every == 0) write_frame(step);
  }
  if (o.element_bench > 0) {
    // CPU time of this process (less sensitive to other jobs than wall time); min and median.
    auto                cpu_ms = [] { return 1e3 * ProcessCpuTime(); };
    std::vector<double> loop_ms;
    for (PetscInt r = 0; r < o.element_bench; ++r) { // the step's pass: rhs zeroed, the state's figures too
      const double           c1 = cpu_ms();
      physics::ElementEnergy energy;
      FemAssembleElements(&sim, &energy);
      loop_ms.push_back(cpu_ms() - c1);
    }
    // The run guard's figures by their definitions (FemTotalEnergy: fem_energy's scalar walk over all
    // elements with their stored K0; FemInvertedFraction), what the health check cost per step when it
    // walked the elements a second time; the element loop above includes them now.
    std::vector<double> definition_ms;
    for (PetscInt r = 0; r < o.element_bench; ++r) {
      const double c0 = cpu_ms();
      const double e  = FemTotalEnergy(sim) + FemInvertedFraction(sim);
      definition_ms.push_back(cpu_ms() - c0);
      if (!std::isfinite(e)) break; // (keeps the call from being optimised away)
    }
    // The refill of the same values (collective: on several ranks it includes the exchange).
    std::vector<double> refill_ms;
    for (PetscInt r = 0; r < o.element_bench; ++r) {
      const double c0 = cpu_ms();
      PetscCall(FemSetSystemValues(&sim));
      refill_ms.push_back(cpu_ms() - c0);
    }
    std::sort(loop_ms.begin(), loop_ms.end());
    std::sort(refill_ms.begin(), refill_ms.end());
    std::sort(definition_ms.begin(), definition_ms.end());
    PetscCall(PetscSynchronizedPrintf(
      comm,
      "element_bench rank %d elements %zu coo_blocks %zu loop_ms min %.3f median %.3f ns_per_element %.1f setvalues_ms min %.3f median %.3f scalar_health_ms min %.3f median %.3f\n",
      rank, sim.elements.size(), sim.pattern.rows.size(), loop_ms.front(), loop_ms[loop_ms.size() / 2],
      1e6 * loop_ms.front() / std::max<size_t>(sim.elements.size(), 1), refill_ms.front(),
      refill_ms[refill_ms.size() / 2], definition_ms.front(), definition_ms[definition_ms.size() / 2]));
    PetscCall(PetscSynchronizedFlush(comm, PETSC_STDOUT));
  }
  t_element *= 1e-3;
  t_comm *= 1e-3;
  t_setvalues *= 1e-3;
  t_solve *= 1e-3;

  // ---- summary ------------------------------------------------------------------------------
  // The final state's energy from its element pass (run after the last step for the guard; run here if
  // the loop ended before it), as every step's guard figure: equal to fem_energy's to ~1e-12, without
  // building every element's K0 for the definition's walk.
  {
    FemStepInfo last;
    PetscCall(FemSimulationAssembleState(&sim, &last));
  }
  physics::FemEnergy E;
  E.kinetic           = sim.state_kinetic;
  E.elastic           = sim.state_elastic;
  const auto   P      = physics::linear_momentum(model, v.data());
  double       cen[3] = {0, 0, 0}, mass_sum = 0;
  const double min_vol_ratio = min_volume_ratio();
  {
    const auto w = physics::gravity_forces(model, {1, 1, 1}); // row sums of M (may be < 0 for P2 corners)
    for (int i = 0; i < n_nodes; ++i) {
      for (int d = 0; d < 3; ++d) cen[d] += w[3 * i] * (x[3 * i + d] - X[3 * i + d]);
      mass_sum += w[3 * i];
    }
  }
  const int   steps_div = std::max(steps_done, 1);
  SummaryLine s;
  s.add("program", std::string("fem"));
  s.add("mat_type", std::string(mat_type));
  s.add("ksp_type", std::string(ksp_type));
  s.add("ranks", (long long)size);
  s.add("order", (long long)o.order);
  s.add("elements", (long long)model.element_count());
  s.add("dofs", (long long)3 * n_nodes);
  s.add("nnz", (long long)nnz);
  s.add("steps", (long long)steps_done);
  s.add("timer", std::string(o.cpu_timer ? "cpu" : "wall"));
  s.add("ms_per_step", costs.total_ms() / steps_div);
  s.add("element_ms", 1e3 * t_element / steps_div);
  // The element loop that ran: the scalar reference, or the batched one's body set.
  s.add("element_body", std::string(o.scalar_elements ? "scalar"
                                                      : binbcsr::body_set_name(
                                                          physics::element_body_used(sim.element_body))));
  s.add("setvalues_ms", 1e3 * t_setvalues / steps_div);
  s.add("assembly_ms", 1e3 * (t_element + t_setvalues) / steps_div);
  s.add("comm_ms", 1e3 * t_comm / steps_div);
  s.add("solve_ms", 1e3 * t_solve / steps_div);
  s.add("element_share", costs.total_ms() > 0 ? 1e3 * t_element / costs.total_ms() : 0.0);
  s.add("cg_its", (double)its_total / steps_div);
  costs.add_late(s);
  {
    int levels, transfers; // -gamg_smoother_precision single: what runs on single-precision copies
    GAMGSmootherCopiesCount(sim.sys.gamg_copies, &levels, &transfers);
    s.add("smoother_copies", (long long)levels);
    s.add("transfer_copies", (long long)transfers);
  }
  s.add("pc_rebuilds", (long long)sim.sys.pc_rebuilds); // -reuse_preconditioner_growth's set-ups
  s.add("pc_refits", (long long)sim.sys.pc_refits);     // of them, GAMG's coarse space refitted in place
  s.add("tip_dx", x[3 * tip] - X[3 * tip]);
  s.add("tip_dy", x[3 * tip + 1] - X[3 * tip + 1]);
  s.add("tip_dz", x[3 * tip + 2] - X[3 * tip + 2]);
  s.add("centroid_dx", cen[0] / mass_sum);
  s.add("centroid_dy", cen[1] / mass_sum);
  s.add("centroid_dz", cen[2] / mass_sum);
  s.add("kinetic", E.kinetic);
  s.add("elastic", E.elastic);
  s.add("momentum_x", P[0]);
  s.add("momentum_y", P[1]);
  s.add("momentum_z", P[2]);
  s.add("min_volume_ratio", min_vol_ratio);
  {
    long long all = 0; // summed over the ranks: each counts the elements it assembles
    PetscCallMPI(MPI_Allreduce(&svd_rotations, &all, 1, MPI_LONG_LONG, MPI_SUM, comm));
    s.add("svd_rotations", all);
  }
  s.add("inverted_fraction", inverted_fraction());
  s.add("energy_initial", guard.energy0);
  s.add("energy_final", sim.state_energy);
  s.add("ksp_reason", std::string(KSPConvergedReasons[last_reason]));
  { // in the input's node order: the simulation's numbering depends on the rank count (METIS + RCM)
    std::vector<double> xyz(x.size());
    for (int i = 0; i < n_nodes; ++i)
      for (int d = 0; d < 3; ++d) xyz[3 * i + d] = x[3 * sim.new_of_old[i] + d];
    PetscCall(DriverComparePositions(comm, xyz, s));
  }
  RunGuardAddSummary(s, guard);
  PetscCall(PrintSummary(comm, s));

  PetscCall(FemSimulationDestroy(&sim));
  PetscCall(PetscFinalize());
  return guard.exit_code;
}
