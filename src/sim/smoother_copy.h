// Single-precision binbcsr copies of multigrid level operators for their smoothers.
//
// A smoother only has to damp the error, so its rounding does not reach the solution: the outer Krylov
// method runs on the operator itself and keeps its tolerance on the true system. What the copy buys is
// bytes: the sweeps and the Chebyshev products stream a half (a binbcsr operator, values converted, or a
// coarse AIJ/BAIJ operator read into whole single-precision binbcsr) or a quarter (read into upper-triangle
// storage) of them. Fewer bytes pay where a level streams from memory (the cloth's coarse levels); a
// level that stays in the cache runs the whole product faster than the symmetric one, whose transposed
// half scatters into y (GAMG's coarse levels, docs/fem_timings.md).
//
// SmootherCopyRefill is the one conversion, shared by the cloth's grid multigrid (grid_mg.h) and the
// copies of a GAMG hierarchy below.
#pragma once
#include <petscksp.h>

#include <vector>

// The copy `*copy` of level operator A, made on the first call (*copy null) and refilled in place
// after (same pattern). A may be binbcsr (any communicator; duplicated in its own storage, values
// converted), SeqBAIJ, SeqAIJ or MPIAIJ (read through a COO list into binbcsr, upper-triangle storage if
// `upper`: A must then be symmetric, which a Galerkin product of a symmetric operator is). `upper` is
// read when the copy is made. Other types: PETSC_ERR_SUP naming the type.
PetscErrorCode SmootherCopyRefill(Mat A, PetscBool upper, Mat *copy);

// Whether SmootherCopyRefill takes A.
PetscErrorCode SmootherCopySupported(Mat A, PetscBool *supported);

// -gamg_smoother_precision single: after PCGAMG has built its hierarchy, every level but the coarsest
// smooths and computes its residual on a copy of its operator, and interpolates and restricts through
// copies of the transfers. An operator or transfer is copied once it will serve more than one solve (a
// reused hierarchy, -ksp_reuse_preconditioner: from its first solve on; one GAMG rebuilds at every solve
// keeps its own, except the fine operator, the same Mat refilled, copied from its second solve on); a
// copy is refilled when its operator's values change.
// Levels whose operator SmootherCopyRefill cannot take keep it (an MPIAIJ level some rank holds no rows
// of), and so do transfers that are not SeqAIJ (on more ranks).
struct GAMGSmootherCopies {
  bool             enabled = false;
  PetscBool        upper   = PETSC_FALSE; // -gamg_smoother_storage upper: the AIJ levels' copies symmetric
  std::vector<Mat> source, copy;          // per PCMG level (0, the coarsest, is solved directly)
  // source: the level's operator as GAMG handed it over (copied when it comes again)
  std::vector<PetscObjectState> source_state;   // source's state when copy was last refilled
  std::vector<PetscObjectState> source_nzstate; // source's nonzero state when copy was made
  // the transfers into each level (SeqAIJ from GAMG): P and R = P^T as single-precision binbcsr, so
  // that restriction is a product too. interp_source: GAMG's P, handed back before a set-up that
  // rebuilds the hierarchy (as the levels' own operators are), which reuses it
  std::vector<Mat>              interp_copy, restrict_copy, interp_source;
  std::vector<PetscObjectState> interp_state; // interp_source's state when its copies were made
  // R = P^T in AIJ (the restriction copy's source, transposed again in place when P's values change
  // and its pattern does not) and P's nonzero state when its copies were made
  std::vector<Mat>              restrict_source;
  std::vector<PetscObjectState> interp_nzstate;
};

// Reads -gamg_smoother_precision (double, the default, or single) and -gamg_smoother_storage (whole, the
// default, or upper).
PetscErrorCode GAMGSmootherCopiesFromOptions(MPI_Comm comm, GAMGSmootherCopies *c);
// Call before each solve, after the operator's new values: sets the KSP up (so PCGAMG builds or
// reuses its hierarchy) and brings the copies up to date. A no-op unless enabled and the PC is GAMG.
PetscErrorCode GAMGSmootherCopiesUpdate(KSP ksp, GAMGSmootherCopies *c);
// PCGAMG's own prolongators into PCMG levels 1 .. levels - 1 (*interp[0] null): what PCMG holds, or,
// where a copy is installed, the prolongator it copies. (c may be disabled.)
PetscErrorCode GAMGSmootherCopiesOwnInterpolations(PC pc, const GAMGSmootherCopies *c,
                                                   std::vector<Mat> *interp);
// The levels smoothing on copies and the levels whose transfers are copies (on this rank).
void           GAMGSmootherCopiesCount(const GAMGSmootherCopies &c, int *levels, int *transfers);
PetscErrorCode GAMGSmootherCopiesDestroy(GAMGSmootherCopies *c);
