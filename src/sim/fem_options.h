// The fem driver's options (examples/fem.cpp; every one in docs/fem.md): read and checked from PETSc's
// options database, and the two things the driver derives from them and the mesh alone, the nodes
// -fix and -fix_box hold still and the node reported as the tip.
#pragma once
#include "sim/fem_simulation.h"
#include "physics/tet_mesh.hpp"

#include <petscsys.h>

#include <vector>

struct FemOptions {
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

// Reads every fem option into o (its values are the defaults) and checks them: a clear PETSc error for
// a value out of range, a list of the wrong length, a body set this CPU lacks.
PetscErrorCode FemGetOptions(FemOptions &o);

// Nodes to fix (1) from -fix and -fix_box; throws std::invalid_argument for a malformed -fix.
std::vector<char> FemSelectFixed(const physics::TetMesh &mesh, const FemOptions &o);

// The node whose displacement is reported as "tip": farthest from the fixed nodes' centroid (or the
// node with the largest x when nothing is fixed).
int FemTipNode(const physics::TetMesh &mesh, const std::vector<char> &fixed);
