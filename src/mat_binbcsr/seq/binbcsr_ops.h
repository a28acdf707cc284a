/* MATSEQBINBCSR: the value operations of binbcsr_ops.cpp and the entries of the ops table (binbcsr.cpp)
   next to them: binary I/O (binbcsr_io.cpp), transpose (binbcsr_transpose.cpp), rows and columns
   (binbcsr_rowops.cpp). */
#ifndef BINBCSR_SEQ_OPS_H
#define BINBCSR_SEQ_OPS_H

#include "binbcsr.h"

/* Value operations (binbcsr_ops.cpp) */
PETSC_INTERN PetscErrorCode MatZeroEntries_SeqBinBCSR(Mat);
PETSC_INTERN PetscErrorCode MatScale_SeqBinBCSR(Mat, PetscScalar);
PETSC_INTERN PetscErrorCode MatShift_SeqBinBCSR(Mat, PetscScalar);
PETSC_INTERN PetscErrorCode MatDiagonalSet_SeqBinBCSR(Mat, Vec, InsertMode);
PETSC_INTERN PetscErrorCode MatAXPY_SeqBinBCSR(Mat, PetscScalar, Mat, MatStructure);
PETSC_INTERN PetscErrorCode MatZeroRows_SeqBinBCSR(Mat, PetscInt, const PetscInt[], PetscScalar, Vec, Vec);
PETSC_INTERN PetscErrorCode MatZeroRowsColumns_SeqBinBCSR(Mat, PetscInt, const PetscInt[], PetscScalar, Vec,
                                                          Vec);
PETSC_INTERN PetscErrorCode MatNorm_SeqBinBCSR(Mat, NormType, PetscReal *);
PETSC_INTERN PetscErrorCode MatGetInfo_SeqBinBCSR(Mat, MatInfoType, MatInfo *);

/* MatLoad from a PETSc binary file (the format seqaij and seqbaij write). */
PETSC_INTERN PetscErrorCode MatLoad_SeqBinBCSR(Mat, PetscViewer);
/* MatView for viewers other than ASCII: binary natively, the rest through a seqaij copy. */
PETSC_INTERN PetscErrorCode MatView_SeqBinBCSR_Other(Mat, PetscViewer);
/* MatTranspose: a new layout for the transposed block pattern (any MatReuse). */
PETSC_INTERN PetscErrorCode MatTranspose_SeqBinBCSR(Mat, MatReuse, Mat *);

/* Rows and columns of the full matrix (binbcsr_rowops.cpp) */
PETSC_INTERN PetscErrorCode MatDiagonalScale_SeqBinBCSR(Mat, Vec, Vec);
/* MatGetRowMaxAbs/Max/Min/MinAbs, kind a binbcsr::row_extreme_kind (instantiated for the four) */
template <int kind> PetscErrorCode MatGetRowExtreme_SeqBinBCSR(Mat, Vec, PetscInt[]);
PETSC_INTERN PetscErrorCode        MatGetColumnReductions_SeqBinBCSR(Mat, PetscInt, PetscReal *);
PETSC_INTERN PetscErrorCode        MatMissingDiagonal_SeqBinBCSR(Mat, PetscBool *, PetscInt *);
PETSC_INTERN PetscErrorCode        MatEqual_SeqBinBCSR(Mat, Mat, PetscBool *);
/* red[j] (cmap->n, zeroed here) = the binbcsr::reduction_kind over point column j of the full matrix */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRColumnReductions(Mat, int kind, double *red);

#endif
