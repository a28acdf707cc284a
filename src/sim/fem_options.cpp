#include "sim/fem_options.h"

#include "physics/element_batch.hpp"
#include "physics/tet_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

PetscErrorCode FemGetOptions(FemOptions &o)
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
  PetscBool mesh_given;
  PetscCall(PetscOptionsString("-mesh", "gmsh mesh (.msh 2.2/4.1 ASCII) or geometry (.geo, meshed by gmsh)",
                               "", o.mesh, o.mesh, sizeof o.mesh, &mesh_given));
  PetscCheck(!mesh_given || o.mesh[0], PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG,
             "-mesh needs a file name (.msh or .geo); without -mesh the driver meshes a box (-mesh_box)");
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
  for (int d = 0; o.fix_box_set && d < 3; ++d) // a NaN or a lower corner above the upper fixed nothing
    PetscCheck(
      std::isfinite(o.fix_box[d]) && std::isfinite(o.fix_box[d + 3]) && o.fix_box[d] <= o.fix_box[d + 3],
      PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
      "-fix_box x0,y0,z0,x1,y1,z1: the corners must be finite with x0 <= x1, y0 <= y1, z0 <= z1 (axis %c: "
      "%g, %g)",
      "xyz"[d], (double)o.fix_box[d], (double)o.fix_box[d + 3]);
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

std::vector<char> FemSelectFixed(const physics::TetMesh &mesh, const FemOptions &o)
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

int FemTipNode(const physics::TetMesh &mesh, const std::vector<char> &fixed)
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
