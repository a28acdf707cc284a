// Loading a PETSc binary matrix file (MatView's format, as `-dump_matrix` and `spmv_bench -save_dir`
// write it) for the benchmarks, checked before MatLoad.
#pragma once
#include <petscmat.h>

#include <string>

// Checks the file on rank 0 (collective): the header, row lengths (none negative, their sum the stored
// count), column indices (in [0, N)) and values (finite). PETSc 3.18's MatLoad of AIJ takes a file with
// a negative row length whose lengths still sum to the count (the matrix then crashed MatIsSymmetric),
// drops a negative column index without a word, keeps a column past N (seqaij products then ran where
// the other formats refused), and loads NaN. PETSC_ERR_FILE_UNEXPECTED naming the file and the first
// fault. rows, cols (may be null): the sizes the file states, on every rank.
PetscErrorCode CheckMatrixFile(MPI_Comm comm, const std::string &path, PetscInt *rows = nullptr,
                               PetscInt *cols = nullptr);

// The checked file loaded as AIJ on comm (PETSc's default row layout); bs > 0 sets the block size (a
// clear error naming the file where it does not divide the sizes), else it comes from the file's .info
// or -matload_block_size.
PetscErrorCode LoadMatrixFile(MPI_Comm comm, const std::string &path, PetscInt bs, Mat *A);
