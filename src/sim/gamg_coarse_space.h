// A new coarse space for PCGAMG's plain-aggregation hierarchy without a new hierarchy.
//
// When the FE driver sets GAMG up again (-reuse_preconditioner_growth), the reason is the coarse space:
// GAMG's tentative prolongator holds, per aggregate, an orthonormal basis of the rigid body modes of the
// shape it was built on, and a turning body leaves them behind. The aggregates themselves depend only on
// the matrix graph, which a fixed pattern keeps. So the prolongators can be refitted in place: per
// aggregate, the QR factorisation PCGAMG's formProl0 makes (the modes of the current coordinates stacked
// over the aggregate's nodes, Q into the prolongator's rows, R as the next level's modes), level after
// level; PCGAMG then needs only its Galerkin products again (-pc_gamg_reuse_interpolation). That is the
// coarse space a full set-up builds on the same aggregates, for a fraction of its cost (docs/fem.md).
#pragma once
#include <petscksp.h>

#include <vector>

// interp[l], l = 1 .. levels - 1: PCGAMG's own prolongator into PCMG level l (SeqAIJ or MPIAIJ; the
// finest level is levels - 1), refitted in place to the rigid body modes of `coords` (x, y, z per node
// of this rank's rows of the finest level, `nodes` of them). Collective on comm. Every rank gathers every
// node's modes and aggregate, factors every aggregate the same way (an aggregate may hold nodes of
// several ranks) and writes its own rows, existing entries only: the patterns stay. *refit is
// PETSC_FALSE, with nothing changed, where the hierarchy is not one this can refit: a prolongator that is
// not AIJ or not plain aggregation (a row reaching into two aggregates: smoothed aggregation), rows
// that are not this rank's nodes by three, a refitted entry the prolongator's pattern lacks, or a
// coordinate that is not finite. Then the caller sets GAMG up from scratch.
PetscErrorCode GAMGRefitCoarseSpace(MPI_Comm comm, const std::vector<Mat> &interp, const PetscReal *coords,
                                    PetscInt nodes, PetscBool *refit);
