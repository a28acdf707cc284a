// The grid multigrid's AIJ levels (grid_mg.h): the coarse levels of more ranks, made by each rank's share of
// the block Galerkin products (summed by COO) or by PCMG's MatPtAP, and their slab smoothers, taken from
// each rank's rows of the AIJ operator. Shared by grid_mg.cpp only.
#pragma once
#include "sim/grid_mg.h"

// This rank's rows of A (AIJ, 3 unknowns per node; MPIAIJ: its diagonal and off-diagonal part) as 3x3
// blocks: their global block rows and columns, and where each entry sits (gather, 9 per block, row-major:
// an index into the diagonal part's values, or into the off-diagonal part's past diagonal_count; -1: not
// stored). Returns an empty string, or why A cannot be read so.
PetscErrorCode GridMGAijBlocks(Mat A, std::vector<PetscInt> *gather, PetscInt *diagonal_count,
                               std::vector<PetscInt> *rows, std::vector<PetscInt> *cols, std::string *why);
// blocks[q] = the value gather[q] points to (0 for -1).
PetscErrorCode GridMGAijGather(Mat A, const std::vector<PetscInt> &gather, PetscInt diagonal_count,
                               std::vector<PetscScalar> *blocks);

// The AIJ matrix of coarse level c whose COO list is every rank's share Ac (SeqBAIJ in the level's physics
// numbering, all its nodes), entry by entry in Ac's value order.
PetscErrorCode GridMGShareTarget(MPI_Comm comm, Mat Ac, const GridMG::DistributedLevel &c, Mat *target);
// The distributed products for new fine values (GridMGRefill with mg->distributed).
PetscErrorCode GridMGDistributedRefill(GridMG *mg, const PetscScalar *coo_values);

// Level `level` sweeps slabs only where every rank's rows can be (why: this rank's reason they cannot, or
// empty); else all ranks keep SOR there (a level's smoother is one collective object), mg->slabs[level]
// is cleared and -info says why. Sets and returns mg->slab_used[level]. Collective on mg->pc.
PetscErrorCode GridMGAgreeOnSlabs(GridMG *mg, PetscInt level, const std::string &why, GridMG::SlabUse *use);

// Makes spc (a coarse level's pre- or post-smoother PC, KSPRICHARDSON) the PCSHELL that sweeps slabs of
// this rank's rows of the level's AIJ operator, decided at its first set-up with the other ranks (SOR
// where they cannot all sweep slabs).
PetscErrorCode GridMGAijSmoother(PC spc, GridMG::AijSlab *a);
