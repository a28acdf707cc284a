// Why a solve ended with KSP_DIVERGED_PC_FAILED. KSPConvergedReason only says that the preconditioner
// failed; PETSc records what failed in the PC that failed (PCGetFailedReason): inside a multigrid
// hierarchy or a block preconditioner that is a level's smoother or a block, while the top PC says
// SUBPC_ERROR or nothing. A driver that stops on the failure names the inner PC and its reason, so that
// the user knows which option to change (GAMG's 6 x 6 coarse blocks under -mg_levels_pc_type pbjacobi
// on linear_38k: "level 2 smoother: FACTOR_NUMERIC_ZEROPIVOT").
#pragma once
#include <petscksp.h>

#include <string>

// *what: where the failed PC sits ("preconditioner", "level L smoother", "coarse solve", "block B",
// nested ones joined by ", ") and its reason (PCFailedReasons' name), the first failure on the lowest
// rank that has one ("... on rank R" on more ranks); empty when no PC records a failure. Collective on
// ksp.
PetscErrorCode DescribePCFailure(KSP ksp, std::string *what);
