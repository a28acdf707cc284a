#include "sim/fem_simulation.h"
#include "sim/summary.h"
#include "physics/element_batch.hpp"
#include "physics/partition.hpp"
#include "physics/row_order.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

static PetscLogEvent FEM_Elements = 0;

/* -log_view events of the driver layer (the physics library has no PETSc): the element loop, i.e. the
   batched kernels (rotations, rotated blocks, forces) with their gather and write-out. */
static PetscErrorCode FemRegisterEvents(void)
{
  static PetscClassId classid = 0;
  PetscFunctionBegin;
  if (classid) PetscFunctionReturn(0);
  PetscCall(PetscClassIdRegister("FEM", &classid));
  PetscCall(PetscLogEventRegister("FemElements", classid, &FEM_Elements));
  PetscFunctionReturn(0);
}

PetscErrorCode FemSimulationCreate(MPI_Comm comm, const FemScene &scene, FemSimulation *sim)
{
  PetscMPIInt rank, size;
  std::string error;

  PetscFunctionBegin;
  PetscCall(FemRegisterEvents());
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  sim->comm = comm;
  sim->rank = rank;
  sim->size = size;
  // What the Mat stores decides the row grouping and the blocks listed below: upper-triangle storage
  // wants rows grouped by their upper length, which the order itself decides.
  PetscBool upper_only = PETSC_FALSE, offrank_full = PETSC_FALSE, lower_mirrored = PETSC_FALSE;
  PetscInt  bin_width = 0;
  PetscCall(BlockSystemStoredTriangle(comm, &upper_only, &offrank_full, &bin_width, &lower_mirrored));
  if (bin_width < 1) bin_width = 8; // sbaij has no bins; measure padding as binbcsr's default would
  try {
    physics::TetMesh mesh = scene.mesh;
    sim->fixed            = scene.fixed.empty() ? std::vector<char>(mesh.node_count(), 0) : scene.fixed;
    if ((int)sim->fixed.size() != mesh.node_count())
      throw std::invalid_argument("fixed-node flags do not match the mesh");
    if (scene.reorder) {
      const physics::AdjacencyGraph g =
        physics::graph_from_elements(mesh.node_count(), mesh.nodes_per_element(), mesh.elements);
      physics::Renumbering r;
      if (size > 1) {
        physics::PartitionOptions po;
        po.local_order = physics::LocalOrder::ReverseCuthillMcKee;
        r              = physics::partition_graph(g, size, po);
      } else {
        r = physics::reorder_for_locality(g, physics::LocalOrder::ReverseCuthillMcKee);
      }
      if (scene.bin_order_window > 0) {
        if (upper_only)
          r = physics::group_by_upper_row_length(g, sim->fixed, r, scene.bin_order_window, (int)bin_width);
        else
          r = physics::group_by_row_length(physics::row_lengths_without_fixed(g, sim->fixed), r,
                                           scene.bin_order_window);
      }
      physics::renumber_nodes(mesh, r.new_of_old);
      physics::sort_elements_by_lowest_node(mesh);
      physics::cluster_elements(mesh, physics::kElementLanes *
                                        physics::write_group_batches(mesh.nodes_per_element()));
      std::vector<char> f(sim->fixed.size());
      for (size_t i = 0; i < f.size(); ++i) f[r.new_of_old[i]] = sim->fixed[i];
      sim->fixed        = f;
      sim->new_of_old   = r.new_of_old;
      sim->part_offsets = r.part_offsets;
    } else {
      sim->new_of_old.resize(mesh.node_count());
      for (int i = 0; i < mesh.node_count(); ++i) sim->new_of_old[i] = i;
      sim->part_offsets.assign(size + 1, 0);
      for (int p = 0; p <= size; ++p) sim->part_offsets[p] = (int)((long long)mesh.node_count() * p / size);
    }
    sim->model = physics::make_fem_model(mesh, scene.settings);
  } catch (const std::exception &ex) {
    error = ex.what();
  }
  PetscCheck(error.empty(), comm, PETSC_ERR_USER_INPUT, "%s", error.c_str());
  PetscCheck(scene.dt > 0 && std::isfinite(scene.dt), comm, PETSC_ERR_ARG_OUTOFRANGE,
             "time step must be positive");

  const int n_nodes = sim->model.node_count(), npe = sim->model.npe;
  sim->own_begin = sim->part_offsets[rank];
  sim->own_end   = sim->part_offsets[rank + 1];
  {
    const std::vector<int> owner =
      physics::assign_elements_to_parts(sim->model.mesh.elements, npe, sim->part_offsets);
    for (int e = 0; e < sim->model.element_count(); ++e)
      if (owner[e] == rank) sim->elements.push_back(e);
  }
  physics::LowerTriangle lower; // list and compute only the blocks the Mat type stores or cannot mirror
  lower.drop = upper_only || lower_mirrored;
  if (upper_only && offrank_full && !lower_mirrored) lower.part_offsets = sim->part_offsets;
  sim->pattern = physics::make_block_pattern(sim->model, sim->elements, sim->fixed, sim->own_begin,
                                             sim->own_end, scene.merge_blocks, lower);
  PetscCall(BlockSystemCreate(comm, n_nodes, sim->own_end - sim->own_begin, sim->pattern.rows,
                              sim->pattern.cols, &sim->sys));
  PetscCheck(sim->sys.row_begin == 3 * sim->own_begin && sim->sys.row_end == 3 * sim->own_end,
             PETSC_COMM_SELF, PETSC_ERR_PLIB, "matrix ownership does not match the node partition");

  /* the rest positions' rigid body modes: PCGAMG's near null space (on linear_38k, rtol 1e-8, 17 CG
     iterations per solve instead of 46-48 with GAMG's default, the translations alone); given again,
     from the current positions, before a set-up forced by -reuse_preconditioner_growth */
  sim->rigid_body_modes = scene.rigid_body_modes;
  if (scene.rigid_body_modes)
    PetscCall(
      BlockSystemSetRigidBodyModes(&sim->sys, sim->model.mesh.nodes.data() + 3 * (size_t)sim->own_begin));
  PetscCheck(
    scene.rayleigh_alpha >= 0 && scene.rayleigh_beta >= 0 && std::isfinite(scene.rayleigh_alpha) &&
      std::isfinite(scene.rayleigh_beta),
    PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
    "Rayleigh damping alpha %g, beta %g: both must be finite and >= 0 (negative damping adds energy)",
    scene.rayleigh_alpha, scene.rayleigh_beta);
  sim->x = sim->model.mesh.nodes;
  sim->v.assign(sim->x.size(), 0.0);
  sim->f_gravity         = physics::gravity_forces(sim->model, scene.gravity);
  sim->dt                = scene.dt;
  sim->is_static         = scene.is_static;
  sim->coefficients      = scene.is_static ? physics::StepCoefficients{1, 0, 0, 0, 1}
                                           : physics::implicit_euler_coefficients(scene.dt, scene.rayleigh_alpha,
                                                                                  scene.rayleigh_beta);
  sim->rhs_gravity_scale = scene.is_static ? 1.0 : scene.dt;
  const size_t n_own     = (size_t)(sim->own_end - sim->own_begin);
  sim->rhs_full.assign(3 * (size_t)n_nodes, 0.0);
  sim->dv_full.assign(3 * (size_t)n_nodes, 0.0);
  sim->rhs_local.assign(3 * n_own, 0.0);
  sim->dv_local.assign(3 * n_own, 0.0);
  sim->counts.resize(size);
  sim->displs.resize(size);
  for (int p = 0; p < size; ++p) {
    sim->counts[p] = 3 * (sim->part_offsets[p + 1] - sim->part_offsets[p]);
    sim->displs[p] = 3 * sim->part_offsets[p];
  }
  PetscFunctionReturn(0);
}

namespace {

// dv_local (the last step's dv, when a step was solved) becomes the next solve's guess, extrapolated by
// sim->guess_order from the dv before it, and joins the history.
PetscErrorCode ExtrapolateGuess(FemSimulation *sim)
{
  PetscFunctionBegin;
  if (sim->guess_order <= 0 || sim->dv_solved == 0 || sim->is_static) PetscFunctionReturn(0); // (Newton: dx)
  std::vector<double> &dv = sim->dv_local, &b1 = sim->dv_before[0], &b2 = sim->dv_before[1];
  const int            order = std::min(sim->guess_order, sim->dv_solved - 1); // what the history allows
  b1.resize(dv.size());
  b2.resize(dv.size());
  for (size_t k = 0; k < dv.size(); ++k) { // one pass: the guess, and the history moved on
    const double last = dv[k], before = b1[k];
    dv[k] = order == 2 ? 3 * (last - before) + b2[k] : order == 1 ? 2 * last - before : last;
    b2[k] = before;
    b1[k] = last;
  }
  PetscFunctionReturn(0);
}

bool SameCoefficients(const physics::StepCoefficients &a, const physics::StepCoefficients &b)
{
  return a.force == b.force && a.stiffness_rhs == b.stiffness_rhs && a.mass_rhs == b.mass_rhs &&
         a.mass_matrix == b.mass_matrix && a.stiffness_matrix == b.stiffness_matrix;
}

// The element pass of the current state, unless the last one ran on it: blocks into values, forces
// into rhs_full, the state's energy and inverted fraction (summed over the ranks). Adds its time, in
// seconds, to *element_s (the pass) and *comm_s (the reduction).
PetscErrorCode ElementPass(FemSimulation *sim, double *element_s, double *comm_s, long long *svd_rotations)
{
  PetscFunctionBegin;
  if (FemStateAssembled(*sim) && SameCoefficients(sim->coefficients, sim->prepared_coefficients))
    PetscFunctionReturn(0);
  const auto             now = sim->cpu_timer ? ProcessCpuTime : WallTime;
  const double           t0  = now();
  physics::ElementEnergy energy;
  PetscCall(PetscLogEventBegin(FEM_Elements, 0, 0, 0, 0));
  const long long svd = FemAssembleElements(sim, &energy);
  PetscCall(PetscLogFlops(physics::element_kernel_flops(sim->model.mesh.order, true) *
                          (PetscLogDouble)sim->elements.size()));
  PetscCall(PetscLogEventEnd(FEM_Elements, 0, 0, 0, 0));
  *svd_rotations += svd;
  const double t1       = now();
  double       local[3] = {energy.elastic, energy.kinetic, energy.inverted}, all[3];
  if (sim->size > 1) PetscCallMPI(MPI_Allreduce(local, all, 3, MPI_DOUBLE, MPI_SUM, sim->comm));
  else std::copy(local, local + 3, all);
  const double t2 = now();
  double       w  = 0; // the work of gravity (every rank holds the whole state)
  for (size_t k = 0; k < sim->x.size(); ++k) w += sim->f_gravity[k] * (sim->x[k] - sim->model.mesh.nodes[k]);
  sim->state_energy            = all[1] + all[0] - w;
  sim->state_kinetic           = all[1];
  sim->state_elastic           = all[0];
  sim->state_inverted_fraction = sim->model.element_count() ? all[2] / sim->model.element_count() : 0.0;
  sim->prepared_x              = sim->x;
  sim->prepared_v              = sim->v;
  sim->prepared_coefficients   = sim->coefficients;
  sim->prepared                = true;
  *element_s += (t1 - t0) + (now() - t2);
  *comm_s += t2 - t1;
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode FemSimulationAssembleState(FemSimulation *sim, FemStepInfo *info)
{
  PetscFunctionBegin;
  const auto   now       = sim->cpu_timer ? ProcessCpuTime : WallTime;
  const double t0        = now();
  double       element_s = 0, comm_s = 0;
  PetscCall(ElementPass(sim, &element_s, &comm_s, &info->svd_rotations));
  info->element_ms += 1e3 * element_s;
  info->comm_ms += 1e3 * comm_s;
  info->total_ms += 1e3 * (now() - t0);
  info->energy            = sim->state_energy;
  info->inverted_fraction = sim->state_inverted_fraction;
  PetscFunctionReturn(0);
}

PetscErrorCode FemSimulationStep(FemSimulation *sim, FemStepInfo *info)
{
  PetscFunctionBegin;
  const auto   now       = sim->cpu_timer ? ProcessCpuTime : WallTime;
  const double t0        = now();
  double       element_s = 0, pass_comm_s = 0;
  info->svd_rotations = 0;
  PetscCall(ElementPass(sim, &element_s, &pass_comm_s, &info->svd_rotations));
  const double t1 = now();
  if (sim->size > 1)
    PetscCallMPI(MPI_Reduce_scatter(sim->rhs_full.data(), sim->rhs_local.data(), sim->counts.data(),
                                    MPI_DOUBLE, MPI_SUM, sim->comm));
  else std::copy(sim->rhs_full.begin(), sim->rhs_full.end(), sim->rhs_local.begin());
  for (int i = sim->own_begin; i < sim->own_end; ++i)
    for (int d = 0; d < 3; ++d) {
      double &r = sim->rhs_local[3 * (i - sim->own_begin) + d];
      r         = sim->fixed[i] ? 0.0 : r + sim->rhs_gravity_scale * sim->f_gravity[3 * i + d];
    }
  const double t2 = now();
  PetscCall(FemSetSystemValues(sim));
  const double t3 = now();
  PetscCall(ExtrapolateGuess(sim));
  // a set-up again (-reuse_preconditioner_growth) builds GAMG's coarse space from the current shape's
  // rigid body modes: the rest shape's, turned with the body, fit it less and less (docs/fem_timings.md)
  if (sim->sys.rebuild_next && sim->rigid_body_modes)
    PetscCall(BlockSystemSetRigidBodyModes(&sim->sys, sim->x.data() + 3 * (size_t)sim->own_begin));
  PetscCall(BlockSystemSolve(&sim->sys, sim->rhs_local.data(), sim->dv_local.data(), &info->stats));
  const double t4 = now();
  if (sim->size > 1)
    PetscCallMPI(MPI_Allgatherv(sim->dv_local.data(), (int)sim->dv_local.size(), MPI_DOUBLE,
                                sim->dv_full.data(), sim->counts.data(), sim->displs.data(), MPI_DOUBLE,
                                sim->comm));
  else std::copy(sim->dv_local.begin(), sim->dv_local.end(), sim->dv_full.begin());
  info->finite = true;
  for (double d : sim->dv_full) info->finite = info->finite && std::isfinite(d);
  if (info->finite) {
    if (sim->is_static) {
      for (size_t k = 0; k < sim->x.size(); ++k) sim->x[k] += sim->dv_full[k];
    } else {
      for (size_t k = 0; k < sim->x.size(); ++k) {
        sim->v[k] += sim->dv_full[k];
        sim->x[k] += sim->dt * sim->v[k];
      }
    }
  } else {
    std::fill(sim->dv_local.begin(), sim->dv_local.end(), 0.0); // not a usable initial guess
    sim->dv_solved = 0;
  }
  if (info->finite) ++sim->dv_solved;
  const double t5    = now();
  info->element_ms   = 1e3 * element_s;
  info->comm_ms      = 1e3 * ((t1 - t0 - element_s) + (t2 - t1) + (t5 - t4));
  info->setvalues_ms = 1e3 * (t3 - t2);
  info->solve_ms     = 1e3 * (t4 - t3);
  info->total_ms     = 1e3 * (t5 - t0);
  PetscFunctionReturn(0);
}

bool FemStateAssembled(const FemSimulation &sim)
{
  return sim.prepared && sim.x == sim.prepared_x && sim.v == sim.prepared_v;
}

long long FemAssembleElements(FemSimulation *sim, physics::ElementEnergy *energy)
{
  std::fill(sim->rhs_full.begin(), sim->rhs_full.end(), 0.0);
  if (sim->sys.single_values) {
    physics::reset_block_values(sim->pattern, sim->values_single);
    return physics::assemble_elements_single(sim->model, sim->elements, sim->x.data(), sim->v.data(),
                                             sim->coefficients, &sim->pattern, sim->values_single.data(),
                                             sim->rhs_full.data(), nullptr, sim->element_kernel,
                                             sim->element_body, energy);
  }
  physics::reset_block_values(sim->pattern, sim->values);
  return physics::assemble_elements(
    sim->model, sim->elements, sim->x.data(), sim->v.data(), sim->coefficients, &sim->pattern,
    sim->values.data(), sim->rhs_full.data(), nullptr, sim->element_kernel, sim->element_body, energy);
}

PetscErrorCode FemSetSystemValues(FemSimulation *sim)
{
  PetscFunctionBegin;
  if (sim->sys.single_values) PetscCall(BlockSystemSetValuesSingle(&sim->sys, sim->values_single.data()));
  else PetscCall(BlockSystemSetValues(&sim->sys, sim->values.data()));
  PetscFunctionReturn(0);
}

PetscErrorCode FemSimulationDestroy(FemSimulation *sim)
{
  PetscFunctionBegin;
  PetscCall(BlockSystemDestroy(&sim->sys));
  *sim = FemSimulation{};
  PetscFunctionReturn(0);
}
