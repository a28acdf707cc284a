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
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

static const char help[] = "Corotational FEM (P1/P2 tetrahedra), implicit Euler, matrix refilled in place.\n"
                           "See docs/fem.md for every option.\n";

namespace {

struct Options {
  char      mesh[PETSC_MAX_PATH_LEN] = "";
  PetscReal mesh_size                = 0;   // for .geo files
  PetscReal mesh_max_elements        = 2e7; // refuse a -mesh_size estimated to give more tetrahedra
  PetscReal box[6]                   = {1, 0.1, 0.1, 20, 2, 2};
  PetscBool box_set                  = PETSC_FALSE;
  PetscInt  order                    = 1;
  PetscBool corotational             = PETSC_TRUE;
  PetscBool lumped                   = PETSC_FALSE;
  PetscReal young = 1e6, poisson = 0.3, density = 1000;
  PetscReal dt                       = 0.01;
  PetscInt  steps                    = 10;
  PetscReal gravity[3]               = {0, 0, -9.81};
  PetscReal rayleigh[2]              = {0, 0};
  char      fix[256]                 = "";
  PetscReal fix_box[6]               = {0};
  PetscBool fix_box_set              = PETSC_FALSE;
  char      vtk[PETSC_MAX_PATH_LEN]  = "";
  PetscInt  vtk_every                = 1;
  char      dump[PETSC_MAX_PATH_LEN] = "";
  PetscBool merge                    = PETSC_TRUE;
  PetscBool rigid_body_modes         = PETSC_TRUE;
  PetscBool reorder                  = PETSC_TRUE;
  PetscInt  bin_order_window         = FemScene().bin_order_window;
  PetscBool quiet                    = PETSC_FALSE;
  PetscInt  element_bench            = 0;
  PetscBool cpu_timer                = PETSC_FALSE;
  PetscInt  guess_order              = 0; // 0..2: extrapolation order; 3: projection (KSPGuess)
  PetscInt  guess_window             = 20;
  PetscBool scalar_elements          = PETSC_FALSE;
  PetscInt  element_body             = 0; // binbcsr::BodySet: auto
  PetscBool is_static                = PETSC_FALSE;
  PetscReal v0[3]                    = {0, 0, 0};
  PetscReal spin[3]                  = {0, 0, 0};
  PetscReal stretch                  = 1;
  PetscReal perturb[4]               = {-1, 0, 0, 0}; // node, dx, dy, dz (rest numbering)
};

PetscErrorCode GetOptions(Options &o)
{
  PetscInt  n;
  PetscBool set;
  PetscFunctionBegin;
  PetscOptionsBegin(PETSC_COMM_WORLD, nullptr, "FEM driver options", "fem");
  // A list of numbers: PETSc reads at most the array's length and drops the rest without a word
  // (-initial_perturb 27,0,-0.3,-0.35,9 moved the node and ignored the 9), so each list is read into a
  // longer buffer and must hold exactly its count.
  const auto numbers = [&](const char *name, const char *what, PetscReal *value, PetscInt count,
                           PetscBool *given) -> PetscErrorCode {
    PetscReal buf[16];
    PetscInt  got = 16;
    PetscBool here;
    PetscFunctionBeginUser;
    for (PetscInt k = 0; k < count; ++k) buf[k] = value[k];
    PetscCall(PetscOptionsRealArray(name, what, "", buf, &got, &here));
    PetscCheck(!here || got == count, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG,
               "%s needs %s (%" PetscInt_FMT " numbers), got %s%" PetscInt_FMT, name, what, count,
               got == 16 ? "at least " : "", got);
    for (PetscInt k = 0; here && k < count; ++k) value[k] = buf[k];
    if (given) *given = here;
    PetscFunctionReturn(0);
  };
  // One number. PETSc 3.22's PetscOptionsReal refuses inf and nan ("Newly set value inf. greater than
  // allowed bound", not naming the option) before the checks below can say which parameter is wrong: a
  // value that is not finite is taken as given and reaches them.
  const auto real = [&](const char *name, const char *help, PetscReal *value) -> PetscErrorCode {
    PetscReal given = *value;
    PetscBool here;
    PetscFunctionBeginUser;
    PetscCall(PetscOptionsGetReal(nullptr, nullptr, name, &given, &here));
    if (here && !std::isfinite(given)) *value = given;
    else PetscCall(PetscOptionsReal(name, help, "", *value, value, nullptr));
    PetscFunctionReturn(0);
  };
  PetscCall(PetscOptionsString("-mesh", "gmsh mesh (.msh 2.2/4.1 ASCII) or geometry (.geo, meshed by gmsh)",
                               "", o.mesh, o.mesh, sizeof o.mesh, nullptr));
  PetscCall(real("-mesh_size", "gmsh characteristic length for .geo input", &o.mesh_size));
  PetscCheck(o.mesh_size >= 0 && std::isfinite(o.mesh_size), PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-mesh_size must be positive and finite (0: the .geo file's own), not %g", (double)o.mesh_size);
  PetscCall(real("-mesh_max_elements",
                 "a -mesh_size whose mesh would have about more tetrahedra than this is refused",
                 &o.mesh_max_elements));
  PetscCheck(o.mesh_max_elements >= 1 && std::isfinite(o.mesh_max_elements), PETSC_COMM_WORLD,
             PETSC_ERR_ARG_OUTOFRANGE, "-mesh_max_elements must be at least 1 and finite, not %g",
             (double)o.mesh_max_elements);
  PetscCall(numbers("-mesh_box", "lx,ly,lz,nx,ny,nz", o.box, 6, &o.box_set)); // a box of 6 tets per cell
  for (int k = 3; o.box_set && k < 6; ++k) // counts become ints: a value past their range is no count
    PetscCheck(o.box[k] >= 1 && o.box[k] <= 1e6 && o.box[k] == std::floor(o.box[k]), PETSC_COMM_WORLD,
               PETSC_ERR_ARG_OUTOFRANGE,
               "-mesh_box: the cell counts nx,ny,nz must be whole numbers in [1, 1e6], got %g",
               (double)o.box[k]);
  PetscCall(
    PetscOptionsInt("-fem_order", "1 (4-node) or 2 (10-node) tetrahedra", "", o.order, &o.order, nullptr));
  PetscCheck(o.order == 1 || o.order == 2, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-fem_order must be 1 or 2");
  PetscCall(PetscOptionsBool("-fem_corotational", "corotational (1) or plain linear (0) elasticity", "",
                             o.corotational, &o.corotational, nullptr));
  PetscCall(PetscOptionsBool("-fem_mass_lumped", "P2: HRZ-lumped instead of consistent mass", "", o.lumped,
                             &o.lumped, nullptr));
  PetscCall(real("-young", "Young's modulus (Pa)", &o.young));
  PetscCall(real("-poisson", "Poisson's ratio", &o.poisson));
  PetscCall(real("-density", "density (kg/m^3)", &o.density));
  PetscCall(real("-dt", "time step (s)", &o.dt));
  PetscCall(
    PetscOptionsInt("-steps", "time steps (Newton iterations with -static)", "", o.steps, &o.steps, nullptr));
  PetscCall(numbers("-gravity", "gx,gy,gz", o.gravity, 3, nullptr));
  PetscCall(numbers("-rayleigh", "alpha,beta", o.rayleigh, 2, nullptr)); // damping D = alpha M + beta K
  PetscCall(PetscOptionsString("-fix",
                               "none | xmin|xmax|ymin|ymax|zmin|zmax[:fraction of the extent, default 0.01]",
                               "", o.fix, o.fix, sizeof o.fix, nullptr));
  PetscCall(numbers("-fix_box", "x0,y0,z0,x1,y1,z1", o.fix_box, 6, &o.fix_box_set)); // fix the nodes inside
  PetscCall(PetscOptionsString("-vtk", "write PREFIX_NNNN.vtu frames and PREFIX.pvd", "", o.vtk, o.vtk,
                               sizeof o.vtk, nullptr));
  PetscCall(
    PetscOptionsInt("-vtk_every", "write a frame every k steps", "", o.vtk_every, &o.vtk_every, nullptr));
  PetscCall(PetscOptionsString("-dump_matrix", "write the first step's matrix (PETSc binary)", "", o.dump,
                               o.dump, sizeof o.dump, nullptr));
  PetscCall(PetscOptionsBool("-fem_merge_blocks",
                             "sum element blocks into unique COO blocks here (1) or let the Mat do it (0)",
                             "", o.merge, &o.merge, nullptr));
  PetscCall(PetscOptionsBool(
    "-fem_rigid_body_modes",
    "give the matrix the rest shape's rigid body modes as near null space (PCGAMG's coarse space; 0: GAMG's default, translations only)",
    "", o.rigid_body_modes, &o.rigid_body_modes, nullptr));
  PetscCall(PetscOptionsBool("-fem_reorder", "METIS partition / RCM renumbering of the nodes", "", o.reorder,
                             &o.reorder, nullptr));
  PetscCall(PetscOptionsInt("-fem_bin_order_window",
                            "with -fem_reorder: sort nodes by row length in windows of N (0 = off)", "",
                            o.bin_order_window, &o.bin_order_window, nullptr));
  PetscCall(PetscOptionsInt("-fem_element_bench",
                            "after the steps, time the element loop N more times (CPU time)", "",
                            o.element_bench, &o.element_bench, nullptr));
  {
    const char *timers[] = {"wall", "cpu"};
    PetscInt    t        = o.cpu_timer ? 1 : 0;
    PetscCall(PetscOptionsEList("-fem_timer",
                                "per-step timings in wall time or process CPU time (a shared machine)", "",
                                timers, 2, timers[t], &t, nullptr));
    o.cpu_timer = t == 1 ? PETSC_TRUE : PETSC_FALSE;
  }
  {
    const char *guesses[] = {"last", "linear", "quadratic", "projection"};
    PetscCall(PetscOptionsEList(
      "-fem_initial_guess",
      "with -ksp_initial_guess_nonzero: the last step's dv, dv extrapolated from the last two or three "
      "steps, or the combination of the last -fem_guess_window solutions whose right-hand sides best "
      "match this one (PETSc's KSPGuess Fischer, model 3)",
      "", guesses, 4, guesses[o.guess_order], &o.guess_order, nullptr));
    PetscCall(PetscOptionsInt("-fem_guess_window", "solutions kept by -fem_initial_guess projection", "",
                              o.guess_window, &o.guess_window, nullptr));
    PetscCheck(o.guess_window >= 1 && o.guess_window <= 200, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
               "-fem_guess_window %" PetscInt_FMT ": 1 to 200 solutions", o.guess_window);
  }
  {
    const char *kernels[] = {"batched", "scalar"};
    PetscInt    k         = o.scalar_elements ? 1 : 0;
    PetscCall(PetscOptionsEList("-fem_element_kernel",
                                "element loop: batched over SIMD lanes, or the scalar reference", "", kernels,
                                2, kernels[k], &k, nullptr));
    o.scalar_elements = k == 1 ? PETSC_TRUE : PETSC_FALSE;
  }
  {
    const char *sets[4];
    for (int k = 0; k < 4; ++k) sets[k] = binbcsr::body_set_name((binbcsr::BodySet)k);
    PetscCall(PetscOptionsEList("-fem_element_body",
                                "batched element loop compiled for: the best this CPU runs, or one set", "",
                                sets, 4, sets[o.element_body], &o.element_body, nullptr));
  }
  PetscCall(PetscOptionsBool("-fem_quiet", "no progress line per step", "", o.quiet, &o.quiet, nullptr));
  PetscCall(PetscOptionsBool("-static", "solve K(x) dx = f(x) + f_ext by Newton steps instead of time steps",
                             "", o.is_static, &o.is_static, nullptr));
  PetscCall(numbers("-initial_velocity", "vx,vy,vz", o.v0, 3, nullptr));
  PetscCall(numbers("-initial_spin", "wx,wy,wz", o.spin, 3, nullptr)); // rigid, about the centroid
  PetscCall(real("-initial_stretch", "scale initial positions about the centroid", &o.stretch));
  {
    PetscBool perturb;
    PetscCall(
      numbers("-initial_perturb", "node,dx,dy,dz", o.perturb, 4, &perturb)); // e.g. to invert an element
    PetscCheck(!perturb || (o.perturb[0] >= 0 && o.perturb[0] == std::floor(o.perturb[0]) &&
                            o.perturb[0] <= PETSC_MAX_INT),
               PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
               "-initial_perturb: the node must be a node number, got %g", (double)o.perturb[0]);
    for (int d = 1; d < 4; ++d)
      PetscCheck(std::isfinite(o.perturb[d]), PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
                 "-initial_perturb: dx,dy,dz must be finite");
  }
  PetscOptionsEnd();
  PetscCheck(o.dt > 0 && std::isfinite(o.dt), PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-dt must be positive");
  {
    // As -mat_binbcsr_kernel: a set this CPU does not run is an error, not a silent fallback.
    const auto want = (binbcsr::BodySet)o.element_body;
    auto       runs = [](binbcsr::BodySet b) { return physics::element_body_used(b) == b; };
    PetscCheck(want == binbcsr::BodySet::Auto || runs(want), PETSC_COMM_WORLD, PETSC_ERR_SUP_SYS,
               "-fem_element_body %s: this CPU (or this build) lacks it; available: portable%s%s",
               binbcsr::body_set_name(want), runs(binbcsr::BodySet::AVX2) ? ", avx2" : "",
               runs(binbcsr::BodySet::AVX512) ? ", avx512" : "");
  }
  for (int d = 0; d < 3; ++d)
    PetscCheck(std::isfinite(o.gravity[d]) && std::isfinite(o.v0[d]) && std::isfinite(o.spin[d]),
               PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
               "-gravity, -initial_velocity and -initial_spin must be finite");
  PetscCheck(std::isfinite(o.rayleigh[0]) && std::isfinite(o.rayleigh[1]) && std::isfinite(o.stretch),
             PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE, "-rayleigh and -initial_stretch must be finite");
  // 0 puts every node on the centroid: no element has a shape, and so none a rotation to start from
  // (negative values invert the body, the inversion demo)
  PetscCheck(
    o.stretch != 0, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
    "-initial_stretch 0 collapses every element to a point; give a nonzero scale (negative inverts)");
  // D = alpha M + beta K: a negative coefficient feeds energy in instead of taking it out.
  PetscCheck(o.rayleigh[0] >= 0 && o.rayleigh[1] >= 0, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-rayleigh alpha,beta must be >= 0 (negative damping adds energy), got %g,%g",
             (double)o.rayleigh[0], (double)o.rayleigh[1]);
  PetscCheck(o.steps >= 0, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE, "-steps must be >= 0");
  PetscCheck(o.bin_order_window >= 0, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-fem_bin_order_window must be >= 0 (0: off)");
  PetscCheck(o.element_bench >= 0, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-fem_element_bench must be >= 0");
  PetscCheck(o.vtk_every >= 1, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE, "-vtk_every must be >= 1");
  PetscFunctionReturn(0);
}

// Nodes to fix, from -fix and -fix_box.
std::vector<char> SelectFixed(const physics::TetMesh &mesh, const Options &o)
{
  std::vector<char> fixed(mesh.node_count(), 0);
  const auto        bb  = physics::bounding_box(mesh);
  std::string       fix = o.fix;
  if (!fix.empty() && fix != "none") {
    double     fraction = 0.01;
    const auto colon    = fix.find(':');
    if (colon != std::string::npos) {
      // the whole rest must be a number in [0, 1]: atof took "abc", "" and "nan" for 0 (no node fixed
      // past the plane's 1e-9) and 5 fixed every node
      const char *text = fix.c_str() + colon + 1;
      char       *end  = nullptr;
      fraction         = std::strtod(text, &end);
      if (end == text || *end || !(fraction >= 0 && fraction <= 1))
        throw std::invalid_argument("-fix " + std::string(o.fix) +
                                    ": the fraction after ':' must be a number in [0, 1] (of the extent)");
      fix = fix.substr(0, colon);
    }
    if (fix.size() != 4 || fix[0] < 'x' || fix[0] > 'z' || (fix.substr(1) != "min" && fix.substr(1) != "max"))
      throw std::invalid_argument("-fix " + std::string(o.fix) +
                                  ": expected none, xmin, xmax, ymin, ymax, zmin or zmax[:fraction]");
    const int    axis   = fix[0] - 'x';
    const bool   is_min = fix.substr(1) == "min";
    const double extent = bb[3 + axis] - bb[axis];
    const double tol    = std::max(fraction, 1e-9) * extent;
    for (int i :
         physics::nodes_beyond_plane(mesh, axis, is_min ? bb[axis] : bb[3 + axis], is_min ? -1 : 1, tol))
      fixed[i] = 1;
  }
  if (o.fix_box_set)
    for (int i : physics::nodes_in_box(mesh, {o.fix_box[0], o.fix_box[1], o.fix_box[2]},
                                       {o.fix_box[3], o.fix_box[4], o.fix_box[5]}))
      fixed[i] = 1;
  return fixed;
}

// The node whose displacement is reported as "tip": farthest from the fixed nodes' centroid (or the
// node with the largest x when nothing is fixed).
int TipNode(const physics::TetMesh &mesh, const std::vector<char> &fixed)
{
  double c[3] = {0, 0, 0};
  int    nf   = 0;
  for (int i = 0; i < mesh.node_count(); ++i)
    if (fixed[i]) {
      for (int d = 0; d < 3; ++d) c[d] += mesh.nodes[3 * i + d];
      ++nf;
    }
  int    best = 0;
  double bd   = -1;
  for (int i = 0; i < mesh.node_count(); ++i) {
    double dist = 0;
    if (nf)
      for (int d = 0; d < 3; ++d) dist += std::pow(mesh.nodes[3 * i + d] - c[d] / nf, 2);
    else dist = mesh.nodes[3 * i];
    if (dist > bd + 1e-12) {
      bd   = dist;
      best = i;
    }
  }
  return best;
}

} // namespace

int main(int argc, char **argv)
{
  Options     o;
  PetscMPIInt rank, size;

  PetscCall(PetscInitialize(&argc, &argv, nullptr, help));
  PetscCall(PetscBinBCSRRegisterAll());
  MPI_Comm comm = PETSC_COMM_WORLD;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(GetOptions(o));

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
      scene.fixed = SelectFixed(scene.mesh, o);
    } catch (const std::exception &ex) {
      error = ex.what();
    }
    PetscCheck(error.empty(), comm, PETSC_ERR_USER_INPUT, "%s", error.c_str());
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
  const int     tip_input = TipNode(scene.mesh, scene.fixed);
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
  if (!rank && o.vtk[0]) {
    std::error_code ec; // a prefix in a new folder: create it (failure shows up as no frames, reported below)
    const std::filesystem::path parent = std::filesystem::path(o.vtk).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  }
  write_frame(0);
  PetscCheck(rank || !o.vtk[0] || !frames.empty(), PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN,
             "-vtk %s: cannot write %s_0000.vtu", o.vtk, o.vtk);

  // ---- time loop ----------------------------------------------------------------------------
  double             t_element = 0, t_setvalues = 0, t_solve = 0, t_comm = 0, t_total = 0;
  long long          its_total = 0, svd_rotations = 0;
  int                steps_done  = 0;
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
    t_total += info.total_ms;
    its_total += info.stats.iterations;
    svd_rotations += info.svd_rotations;
    last_reason = info.stats.reason;
    steps_done  = step;
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
  t_total *= 1e-3;

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
  s.add("ms_per_step", 1e3 * t_total / steps_div);
  s.add("element_ms", 1e3 * t_element / steps_div);
  // The element loop that ran: the scalar reference, or the batched one's body set.
  s.add("element_body", std::string(o.scalar_elements ? "scalar"
                                                      : binbcsr::body_set_name(
                                                          physics::element_body_used(sim.element_body))));
  s.add("setvalues_ms", 1e3 * t_setvalues / steps_div);
  s.add("assembly_ms", 1e3 * (t_element + t_setvalues) / steps_div);
  s.add("comm_ms", 1e3 * t_comm / steps_div);
  s.add("solve_ms", 1e3 * t_solve / steps_div);
  s.add("element_share", t_total > 0 ? t_element / t_total : 0.0);
  s.add("cg_its", (double)its_total / steps_div);
  {
    int levels, transfers; // -gamg_smoother_precision single: what runs on single-precision copies
    GAMGSmootherCopiesCount(sim.sys.gamg_copies, &levels, &transfers);
    s.add("smoother_copies", (long long)levels);
    s.add("transfer_copies", (long long)transfers);
  }
  s.add("pc_rebuilds", (long long)sim.sys.pc_rebuilds); // -reuse_preconditioner_growth's set-ups
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
