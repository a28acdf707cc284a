#include "sim/matrix_file.h"

#include <sys/stat.h>

#include <cstdio>
#include <vector>

PetscErrorCode CheckMatrixFile(MPI_Comm comm, const std::string &path, PetscInt *rows, PetscInt *cols)
{
  PetscMPIInt rank;
  char        why[256] = "";
  PetscInt    sizes[2] = {0, 0};

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (!rank) {
    int fd;
    PetscCall(PetscBinaryOpen(path.c_str(), FILE_MODE_READ, &fd));
    PetscInt header[4];
    PetscCall(PetscBinaryRead(fd, header, 4, nullptr, PETSC_INT));
    const PetscInt M = header[1], N = header[2], nz = header[3];
    sizes[0] = M, sizes[1] = N;
    if (header[0] != MAT_FILE_CLASSID)
      std::snprintf(why, sizeof why, "not a PETSc matrix (class id %d)", (int)header[0]);
    else if (M < 0 || N < 0 || nz < 0)
      std::snprintf(why, sizeof why, "negative sizes %d x %d, %d entries", (int)M, (int)N, (int)nz);
    else { // sizes the file cannot hold are not allocated: 4 bytes per row length, 12 per entry
      struct stat st;
      if (stat(path.c_str(), &st) == 0 && 16.0 + 4.0 * M + 12.0 * nz > (double)st.st_size)
        std::snprintf(why, sizeof why, "%d rows and %d entries do not fit its %lld bytes", (int)M, (int)nz,
                      (long long)st.st_size);
    }
    if (!why[0]) {
      std::vector<PetscInt> lengths(M), cols(nz);
      PetscInt              read = 0;
      PetscCall(PetscBinaryRead(fd, lengths.data(), M, &read, PETSC_INT));
      long long sum = 0;
      for (PetscInt r = 0; r < M && !why[0]; ++r) {
        if (lengths[r] < 0 || lengths[r] > N)
          std::snprintf(why, sizeof why, "row %d has length %d (N = %d)", (int)r, (int)lengths[r], (int)N);
        sum += lengths[r];
      }
      if (!why[0] && (read != M || sum != nz))
        std::snprintf(why, sizeof why, "the row lengths sum to %lld, not the %d entries stored", sum,
                      (int)nz);
      if (!why[0]) {
        PetscCall(PetscBinaryRead(fd, cols.data(), nz, &read, PETSC_INT));
        if (read != nz)
          std::snprintf(why, sizeof why, "%lld of %d column indices present", (long long)read, (int)nz);
        for (PetscInt k = 0; k < nz && !why[0]; ++k)
          if (cols[k] < 0 || cols[k] >= N)
            std::snprintf(why, sizeof why, "entry %d has column %d, outside [0, %d)", (int)k, (int)cols[k],
                          (int)N);
      }
      if (!why[0]) {
        std::vector<PetscScalar> vals(nz);
        PetscCall(PetscBinaryRead(fd, vals.data(), nz, &read, PETSC_SCALAR));
        if (read != nz) std::snprintf(why, sizeof why, "%lld of %d values present", (long long)read, (int)nz);
        for (PetscInt k = 0; k < nz && !why[0]; ++k)
          if (PetscIsInfOrNanScalar(vals[k]))
            std::snprintf(why, sizeof why, "entry %d is not finite", (int)k);
      }
    }
    PetscCall(PetscBinaryClose(fd));
  }
  PetscCallMPI(MPI_Bcast(why, sizeof why, MPI_CHAR, 0, comm));
  PetscCheck(!why[0], comm, PETSC_ERR_FILE_UNEXPECTED, "%s: %s", path.c_str(), why);
  PetscCallMPI(MPI_Bcast(sizes, 2, MPIU_INT, 0, comm));
  if (rows) *rows = sizes[0];
  if (cols) *cols = sizes[1];
  PetscFunctionReturn(0);
}

PetscErrorCode LoadMatrixFile(MPI_Comm comm, const std::string &path, PetscInt bs, Mat *A)
{
  PetscViewer viewer;

  PetscFunctionBegin;
  PetscInt M, N;
  PetscCall(CheckMatrixFile(comm, path, &M, &N));
  // MatLoad's own refusal ("Local size 1 must be divisible by blocksize 3") names neither the file nor
  // where the block size came from
  PetscCheck(bs <= 0 || (M % bs == 0 && N % bs == 0), comm, PETSC_ERR_ARG_SIZ,
             "%s is %" PetscInt_FMT " x %" PetscInt_FMT ", not whole %" PetscInt_FMT "x%" PetscInt_FMT
             " blocks: give a block size that divides both (-bs; 1 for a scalar matrix)",
             path.c_str(), M, N, bs, bs);
  PetscCall(PetscViewerBinaryOpen(comm, path.c_str(), FILE_MODE_READ, &viewer));
  PetscCall(MatCreate(comm, A));
  PetscCall(MatSetType(*A, MATAIJ));
  if (bs > 0) PetscCall(MatSetBlockSize(*A, bs));
  PetscCall(MatLoad(*A, viewer));
  PetscCall(PetscViewerDestroy(&viewer));
  PetscFunctionReturn(0);
}
