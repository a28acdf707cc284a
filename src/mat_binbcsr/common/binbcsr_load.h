/* The PETSc binary matrix file reader shared by the seq and mpi MatLoad (binbcsr_load.cpp). */
#ifndef BINBCSR_LOAD_H
#define BINBCSR_LOAD_H

#include <petscmat.h>
#include <vector>

/* Reads this rank's rows of the matrix in the file (A's local rows; sizes from the file where A has
   none, block sizes from -matload_block_size) as CSR with global columns. Every length and index is
   checked, and the verdict is the same on every rank, before anything else happens: a bad entry in
   one rank's rows is a clear error on all of them (mpiaij would drop a negative column silently,
   seqaij would read outside x with it). Repeated columns of a row are summed into one entry, sorted
   by column: seqaij stores both and its product sums them, which is the matrix the file means.
   Collective on A. */
PETSC_INTERN PetscErrorCode MatBinBCSRReadBinaryRows_Private(Mat A, PetscViewer viewer,
                                                             std::vector<PetscInt>    &rowptr,
                                                             std::vector<PetscInt>    &cols,
                                                             std::vector<PetscScalar> &vals);

#endif
