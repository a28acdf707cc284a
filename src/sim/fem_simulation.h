// The FEM time stepper on top of BlockSystem: what examples/fem runs and what the tests drive, so
// both use one loop. Physics (element loop, pattern) comes from src/physics; this file adds the
// PETSc solve, the MPI split and the timings.
//
// Parallel layout: every rank holds the whole mesh and state; the nodes are renumbered so that rank
// p owns a contiguous range (METIS partition with RCM inside each part; RCM alone on one rank); each
// rank assembles the elements inside its range and a balancing share of those cut by the partition
// (physics::assign_elements_to_parts); the right-hand side is summed with
// MPI_Reduce_scatter and dv gathered back with MPI_Allgatherv.
#pragma once
#include "sim/sim_system.h"
#include "physics/corotational_assembly.hpp"
#include "physics/fem_model.hpp"

#include <array>
#include <cmath>
#include <string>
#include <vector>

struct FemScene {
  physics::TetMesh      mesh; // order 1 or 2, in the input numbering
  physics::FemSettings  settings;
  std::vector<char>     fixed; // per node of mesh (input numbering); empty = none
  std::array<double, 3> gravity{0, 0, -9.81};
  double                dt             = 0.01;
  double                rayleigh_alpha = 0, rayleigh_beta = 0;
  bool                  is_static    = false; // Newton steps on K(x) dx = f(x) + f_ext instead of time steps
  bool                  merge_blocks = true;
  bool rigid_body_modes = true; // the rest shape's rigid body modes as the matrix's near null space (PCGAMG)
  bool reorder          = true;
  int  bin_order_window =
    256; // with reorder: sort rows by length in windows of this many nodes (physics/row_order.hpp); 0 = off
};

struct FemStepInfo {
  SolveStats stats;
  bool       finite     = true; // dv had no NaN/Inf (else the state was left unchanged)
  double     element_ms = 0, setvalues_ms = 0, comm_ms = 0, solve_ms = 0, total_ms = 0;
  long long  svd_rotations =
    0; // this rank's elements whose rotation took the scalar SVD path (inverted, flat)
  // The state's figures for the run guard, set by FemSimulationAssembleState (NaN until then):
  // kinetic + elastic energy - the work of gravity (FemTotalEnergy's sum), and the fraction of
  // elements whose corner tetrahedron is inverted or flat (FemInvertedFraction's).
  double energy = NAN, inverted_fraction = NAN;
};

struct FemSimulation {
  MPI_Comm                  comm = MPI_COMM_NULL;
  int                       rank = 0, size = 1;
  physics::FemModel         model;      // renumbered mesh
  std::vector<char>         fixed;      // renumbered
  std::vector<int>          new_of_old; // input node -> simulation node
  std::vector<int>          part_offsets;
  int                       own_begin = 0, own_end = 0;
  std::vector<int>          elements; // elements this rank assembles
  physics::BlockPattern     pattern;
  physics::StepCoefficients coefficients;
  BlockSystem               sys;
  std::vector<double>       x, v; // all nodes, simulation numbering, 3 per node
  std::vector<double>       f_gravity;
  double                    dt = 0, rhs_gravity_scale = 0;
  bool                      is_static = false;
  bool rigid_body_modes = false; // the near null space is the rigid body modes (given again at a set-up)
  bool cpu_timer        = false; // FemStepInfo times in process CPU time instead of wall time
  physics::ElementKernel element_kernel = physics::ElementKernel::Batched; // Scalar: the reference loop
  binbcsr::BodySet element_body = binbcsr::BodySet::Auto; // the batched loop's body set (element_batch.hpp)
  // The solve's initial guess (with a nonzero-guess KSP): the last dv (0), or extrapolated from the last
  // two (1, linear) or three (2, quadratic) dv: under smooth motion the next dv is close to that, and
  // the solve starts closer to its answer (linear_38k, GAMG to rtol 1e-6: 16.1 -> 14.15 CG iterations)
  int                 guess_order = 0;
  std::vector<double> dv_before[2];  // the dv of the steps before the last one (local rows), newest first
  int                 dv_solved = 0; // solves since the start (or since a non-finite dv reset the guess)
  // The element pass's state: values and rhs_full hold the blocks and forces of (x, v) as they were at
  // the last pass (copies below), with those coefficients, and state_energy, state_inverted_fraction
  // its figures. A step whose state is still that one reuses them instead of walking the elements
  // again; a caller that writes x or v between steps gets a new pass (the copies tell, at 0.16 ms
  // per step for linear_38k, instead of a rule that every writer must remember).
  bool                      prepared = false;
  std::vector<double>       prepared_x, prepared_v;
  physics::StepCoefficients prepared_coefficients;
  double                    state_energy = NAN, state_inverted_fraction = NAN;
  double                    state_kinetic = NAN, state_elastic = NAN; // state_energy's terms (no gravity)
  // work arrays
  std::vector<double> values, rhs_full, rhs_local, dv_local, dv_full;
  std::vector<float>  values_single; // the blocks instead of values where sys.single_values
  std::vector<int>    counts, displs;
};

// Builds the model and the linear system; x = rest positions, v = 0. Errors in the scene (mesh,
// material) come back as PETSC_ERR_USER_INPUT with the reason.
PetscErrorCode FemSimulationCreate(MPI_Comm comm, const FemScene &scene, FemSimulation *sim);
// One step: the element pass of the current state (unless FemSimulationAssembleState already ran it
// on this state), the refill, the solve, x and v updated. Collective.
PetscErrorCode FemSimulationStep(FemSimulation *sim, FemStepInfo *info);
// The element pass of the current state (unless it already ran on it): the next step's blocks and
// forces, and the state's energy and inverted fraction into info->energy, info->inverted_fraction,
// its time added to info's element_ms, comm_ms and total_ms. Call it after each step for the run
// guard's figures (one walk over the elements serves both the check and the next step), and before
// the first for the initial ones. Collective.
PetscErrorCode FemSimulationAssembleState(FemSimulation *sim, FemStepInfo *info);
PetscErrorCode FemSimulationDestroy(FemSimulation *sim);
// Whether the last element pass ran on the current x and v: state_energy, state_kinetic, state_elastic
// and state_inverted_fraction are then that state's (summed over the ranks).
bool FemStateAssembled(const FemSimulation &sim);
// The element loop of (x, v) itself, which the step's pass times and keeps track of and a benchmark
// calls alone: the blocks into values, or into values_single where the system takes float values, the
// forces into rhs_full (zeroed first), the state's figures into *energy (may be null). Returns the
// elements whose rotation took the scalar path.
long long FemAssembleElements(FemSimulation *sim, physics::ElementEnergy *energy);
// The refill of the system's matrix from the blocks of the last element loop.
PetscErrorCode FemSetSystemValues(FemSimulation *sim);
