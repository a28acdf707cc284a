/* MATSEQBINBCSR: ops-table entries of binbcsr_ops.cpp implemented in the other files of its part
   (binary I/O in binbcsr_io.cpp, transpose in binbcsr_transpose.cpp). */
#ifndef BINBCSR_SEQ_OPS_H
#define BINBCSR_SEQ_OPS_H

#include "binbcsr.h"

/* MatLoad from a PETSc binary file (the format seqaij and seqbaij write). */
PETSC_INTERN PetscErrorCode MatLoad_SeqBinBCSR(Mat, PetscViewer);
/* MatView for viewers other than ASCII: binary natively, the rest through a seqaij copy. */
PETSC_INTERN PetscErrorCode MatView_SeqBinBCSR_Other(Mat, PetscViewer);
/* MatTranspose: a new layout for the transposed block pattern (any MatReuse). */
PETSC_INTERN PetscErrorCode MatTranspose_SeqBinBCSR(Mat, MatReuse, Mat *);

#endif
