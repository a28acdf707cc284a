/*
   Private header of MATMPIBINBCSR.

   Layout (the same split as PETSc's MPIAIJ/MPIBAIJ): rank p owns the (block) rows
   [rstart, rend) and, for a square matrix, the same range of columns. Its rows are stored as

     A  (m x n)            the diagonal part: columns owned by p, numbered from cstart;
     B  (m x nghost*bs)    the off-diagonal part with compressed columns: local column k*bs+c of
                           B is global column garray[k]*bs+c, garray sorted.

   Both parts are sequential matrices of the "inner" type (MATSEQBINBCSR by default, so both get
   the bin layout; -mat_mpibinbcsr_inner_type seqaij|seqbaij exists for comparisons and tests). The
   product y = A x_local + B x_ghost overlaps the ghost exchange (a VecScatter, i.e. a PetscSF) with
   the diagonal-part product:

       begin scatter x -> lvec;  y = A x;  end scatter;  y += B lvec

   Before the first final assembly, off-diagonal entries are kept in a staging map (row, global
   column) -> value; the first final assembly fixes garray from it, builds B and the scatter. Entries
   for rows owned by other ranks are kept in a stash (row, column, value) and sent to their owners
   at assembly through a PetscSF built for that exchange (PETSc's own MatStash is not exported by
   the installed library).
*/
#ifndef MPIBINBCSR_H
#define MPIBINBCSR_H

#include "binbcsr_impl.h"
#include <petsc/private/matimpl.h>
#include <petscsf.h>

#include <unordered_map>
#include <utility>
#include <vector>

/* COO assembly plan: entries of this rank's rows, from the caller's own list or received from other
   ranks, each routed to the A or B part. */
struct MPIBinBCSRCoo {
  PetscCount               n  = 0;       /* length of the caller's coo_v[] */
  PetscSF                  sf = nullptr; /* leaves: entries sent to other ranks; roots: entries received */
  std::vector<PetscCount>  send_from;    /* [nsend] index into coo_v of each sent entry */
  PetscInt                 nrecv = 0;
  std::vector<PetscCount>  a_from, b_from;             /* source of each entry of A's / B's COO list: k < n is
                                              coo_v[k], k >= n is the (k-n)th received value */
  PetscBool                composed = PETSC_FALSE;     /* BIN-BCSR parts hold a_from/b_from composed into
                                                     their own maps (then a_from, b_from, a_v, b_v are empty) */
  std::vector<PetscScalar> sendbuf, recvbuf, a_v, b_v; /* a_v, b_v: only for other inner types */
};

struct Mat_MPIBinBCSR {
  Mat  A = nullptr, B = nullptr; /* diagonal and off-diagonal parts */
  char inner_type[64];           /* type of A and B */

  /* off-diagonal columns: valid once compressed */
  PetscBool             compressed = PETSC_FALSE;
  std::vector<PetscInt> garray;          /* global block column of each local block column of B, sorted */
  Vec                   lvec  = nullptr; /* ghost values, nghost*bs */
  VecScatter            Mvctx = nullptr;

  /* staging of B before the first final assembly: key = local row * N + global column */
  std::unordered_map<long long, PetscScalar> b_staging;

  /* off-process entries waiting for assembly */
  std::vector<PetscInt>    stash_row, stash_col;
  std::vector<PetscScalar> stash_val;
  PetscBool                donotstash  = PETSC_FALSE;
  PetscBool                roworiented = PETSC_TRUE; /* layout of the values given to MatSetValues */

  /* options replayed on A and B when they are (re)created */
  std::vector<std::pair<MatOption, PetscBool>> part_options;
  PetscBool           ignore_new_offdiag = PETSC_FALSE; /* MAT_NEW_NONZERO_LOCATIONS false */
  PetscInt            bin_width          = 0;           /* 0: the inner type's default */
  PetscBool           precision_set      = PETSC_FALSE;
  PetscInt            streams            = 0;  /* MatBinBCSRSetStreams; 0: the parts' default */
  PetscInt            prefetch           = -1; /* MatBinBCSRSetPrefetch; -1: the parts' default */
  PetscInt            xload      = -1; /* MatBinBCSRSetXLoad; -1: not set (the parts' tuners choose) */
  PetscInt            tune       = -1; /* MatBinBCSRSetTune for the parts; -1: theirs */
  PetscInt            tune_cache = -1; /* MatBinBCSRSetTuneCache for the parts; -1: theirs */
  MatBinBCSRKernel    kernel     = MAT_BINBCSR_KERNEL_AUTO; /* MatBinBCSRSetKernel */
  MatBinBCSRPrecision precision  = MAT_BINBCSR_PRECISION_DOUBLE;
  PetscBool           sym        = PETSC_FALSE; /* symmetric storage of the diagonal part (B stays full) */
  PetscBool           coo_mirror = PETSC_FALSE; /* MatBinBCSRSetCOOMirror */

  /* MatGetRow buffers */
  std::vector<PetscInt>    row_cols;
  std::vector<PetscScalar> row_vals;
  PetscBool                getrow_active = PETSC_FALSE;

  /* local rows that have off-diagonal entries (found once the pattern is fixed; MatMultDotLocal) */
  PetscBool                offdiag_rows_known = PETSC_FALSE;
  std::vector<PetscInt>    offdiag_rows;
  std::vector<PetscScalar> offdiag_saved;

  MPIBinBCSRCoo *coo                = nullptr;
  PetscBool      coo_just_assembled = PETSC_FALSE; /* MatSetValuesCOO's own assembly call has nothing to do */
};

static inline Mat_MPIBinBCSR *MPIBinBCSR(Mat mat) { return static_cast<Mat_MPIBinBCSR *>(mat->data); }
static inline PetscInt        MPIBinBCSRGhosts(Mat mat)
{
  return static_cast<PetscInt>(MPIBinBCSR(mat)->garray.size());
}

/* A sequential vector on this rank's part of a parallel one (shares its array). */
struct LocalView {
  Vec                vec = nullptr, seq = nullptr;
  PetscScalar       *a  = nullptr;
  const PetscScalar *ra = nullptr;
  /* read_only: the vector may be read-locked (e.g. x of MatZeroRowsColumns); seq is then only read */
  PetscErrorCode open(Vec v, bool read_only = false)
  {
    PetscInt n;
    PetscFunctionBegin;
    vec = v;
    PetscCall(VecGetLocalSize(v, &n));
    if (read_only) PetscCall(VecGetArrayRead(v, &ra));
    else PetscCall(VecGetArray(v, &a));
    PetscCall(
      VecCreateSeqWithArray(PETSC_COMM_SELF, 1, n, read_only ? const_cast<PetscScalar *>(ra) : a, &seq));
    if (read_only) PetscCall(VecLockReadPush(seq));
    PetscFunctionReturn(0);
  }
  PetscErrorCode close()
  {
    PetscFunctionBegin;
    if (vec) {
      if (ra) PetscCall(VecLockReadPop(seq));
      PetscCall(VecDestroy(&seq));
      if (ra) PetscCall(VecRestoreArrayRead(vec, &ra));
      else PetscCall(VecRestoreArray(vec, &a));
      vec = nullptr;
      ra  = nullptr;
    }
    PetscFunctionReturn(0);
  }
};

/* The configuration of one matrix (inner type, bin width, precision, storage, options replayed on the
   parts) given to another, empty one (mpibinbcsr_convert.cpp): MatDuplicate, MatAXPY, MatTranspose. */
PETSC_INTERN PetscErrorCode MatMPIBinBCSRCopyConfig(Mat from, Mat to);

/* mpibinbcsr_config.cpp: the settings, kept for later parts and forwarded to the existing ones */
PETSC_INTERN PetscErrorCode MatBinBCSRSetBinWidth_MPIBinBCSR(Mat mat, PetscInt bw);
PETSC_INTERN PetscErrorCode MatBinBCSRGetBinWidth_MPIBinBCSR(Mat mat, PetscInt *bw);
PETSC_INTERN PetscErrorCode MatBinBCSRSetStreams_MPIBinBCSR(Mat mat, PetscInt streams);
PETSC_INTERN PetscErrorCode MatBinBCSRGetStreams_MPIBinBCSR(Mat mat, PetscInt *streams);
PETSC_INTERN PetscErrorCode MatBinBCSRSetPrefetch_MPIBinBCSR(Mat mat, PetscInt bytes);
PETSC_INTERN PetscErrorCode MatBinBCSRSetXLoad_MPIBinBCSR(Mat mat, MatBinBCSRXLoad xload);
PETSC_INTERN PetscErrorCode MatBinBCSRGetXLoad_MPIBinBCSR(Mat mat, MatBinBCSRXLoad *xload);
PETSC_INTERN PetscErrorCode MatBinBCSRGetPrefetch_MPIBinBCSR(Mat mat, PetscInt *bytes);
PETSC_INTERN PetscErrorCode MatBinBCSRSetTune_MPIBinBCSR(Mat mat, MatBinBCSRTune t);
PETSC_INTERN PetscErrorCode MatBinBCSRGetTune_MPIBinBCSR(Mat mat, MatBinBCSRTune *t);
PETSC_INTERN PetscErrorCode MatBinBCSRSetTuneCache_MPIBinBCSR(Mat mat, PetscBool flg);
PETSC_INTERN PetscErrorCode MatBinBCSRGetTuneCache_MPIBinBCSR(Mat mat, PetscBool *flg);
PETSC_INTERN PetscErrorCode MatBinBCSRSetPrecision_MPIBinBCSR(Mat mat, MatBinBCSRPrecision p);
PETSC_INTERN PetscErrorCode MatBinBCSRGetPrecision_MPIBinBCSR(Mat mat, MatBinBCSRPrecision *p);
PETSC_INTERN PetscErrorCode MatBinBCSRSetSymmetricStorage_MPIBinBCSR(Mat mat, PetscBool flg);
PETSC_INTERN PetscErrorCode MatBinBCSRGetSymmetricStorage_MPIBinBCSR(Mat mat, PetscBool *flg);
PETSC_INTERN PetscErrorCode MatBinBCSRSetCOOMirror_MPIBinBCSR(Mat mat, PetscBool flg);
PETSC_INTERN PetscErrorCode MatBinBCSRGetCOOMirror_MPIBinBCSR(Mat mat, PetscBool *flg);

/* mpibinbcsr.cpp: creating the parts, compressing B, the ghost scatter */
PETSC_INTERN PetscErrorCode MatMPIBinBCSRCreatePart(Mat, PetscInt m, PetscInt n, Mat *);
/* Layouts set up, an unset block size (-1: the program never gave one) made 1: every preallocation
   path starts here, so that the parts and the ghost columns may read mat->rmap/cmap->bs. */
PETSC_INTERN PetscErrorCode MatMPIBinBCSRSetUpLayouts(Mat);
PETSC_INTERN PetscErrorCode MatMPIBinBCSRResetParts(Mat);
PETSC_INTERN PetscErrorCode MatMPIBinBCSRSetUpScatter(Mat);
PETSC_INTERN PetscErrorCode MatMPIBinBCSRGhostIndex(Mat, PetscInt gcol, PetscInt *lcol);
PETSC_INTERN PetscErrorCode MatMPIBinBCSRBuildSendSF(MPI_Comm, PetscInt nsend, const PetscMPIInt dest[],
                                                     PetscSF *, PetscInt *nrecv);

/* mpibinbcsr_assembly.cpp */
PETSC_INTERN PetscErrorCode MatSetValues_MPIBinBCSR(Mat, PetscInt, const PetscInt[], PetscInt,
                                                    const PetscInt[], const PetscScalar[], InsertMode);
PETSC_INTERN PetscErrorCode MatAssemblyBegin_MPIBinBCSR(Mat, MatAssemblyType);
PETSC_INTERN PetscErrorCode MatAssemblyEnd_MPIBinBCSR(Mat, MatAssemblyType);
PETSC_INTERN PetscErrorCode MatSetPreallocationCOO_MPIBinBCSR(Mat, PetscCount, const PetscInt[],
                                                              const PetscInt[]);
PETSC_INTERN PetscErrorCode MatSetValuesCOO_MPIBinBCSR(Mat, const PetscScalar[], InsertMode);
PETSC_INTERN PetscErrorCode MatBinBCSRSetValuesCOOSingle_MPIBinBCSR(Mat, const float[], InsertMode);
PETSC_INTERN PetscErrorCode MatMPIBinBCSRDestroyCoo(Mat);

/* mpibinbcsr_ops.cpp */
PETSC_INTERN PetscErrorCode MatMult_MPIBinBCSR(Mat, Vec, Vec);
PETSC_INTERN PetscErrorCode MatMultAdd_MPIBinBCSR(Mat, Vec, Vec, Vec);
PETSC_INTERN PetscErrorCode MatMultTranspose_MPIBinBCSR(Mat, Vec, Vec);
PETSC_INTERN PetscErrorCode MatMultTransposeAdd_MPIBinBCSR(Mat, Vec, Vec, Vec);
PETSC_INTERN PetscErrorCode MatMultDotLocal_MPIBinBCSR(Mat, Vec, Vec, PetscScalar *);
PETSC_INTERN PetscErrorCode MatGetDiagonal_MPIBinBCSR(Mat, Vec);
PETSC_INTERN PetscErrorCode MatDiagonalSet_MPIBinBCSR(Mat, Vec, InsertMode);
PETSC_INTERN PetscErrorCode MatInvertBlockDiagonal_MPIBinBCSR(Mat, const PetscScalar **);
PETSC_INTERN PetscErrorCode MatInvertVariableBlockDiagonal_MPIBinBCSR(Mat, PetscInt, const PetscInt *,
                                                                      PetscScalar *);
PETSC_INTERN PetscErrorCode MatSOR_MPIBinBCSR(Mat, Vec, PetscReal, MatSORType, PetscReal, PetscInt, PetscInt,
                                              Vec);
PETSC_INTERN PetscErrorCode MatMultDiagonalBlock_MPIBinBCSR(Mat, Vec, Vec); /* mpibinbcsr_sor.cpp */
PETSC_INTERN PetscErrorCode MatScale_MPIBinBCSR(Mat, PetscScalar);
PETSC_INTERN PetscErrorCode MatShift_MPIBinBCSR(Mat, PetscScalar);
PETSC_INTERN PetscErrorCode MatZeroEntries_MPIBinBCSR(Mat);
PETSC_INTERN PetscErrorCode MatZeroRows_MPIBinBCSR(Mat, PetscInt, const PetscInt[], PetscScalar, Vec, Vec);
PETSC_INTERN PetscErrorCode MatZeroRowsColumns_MPIBinBCSR(Mat, PetscInt, const PetscInt[], PetscScalar, Vec,
                                                          Vec);
PETSC_INTERN PetscErrorCode MatGetRow_MPIBinBCSR(Mat, PetscInt, PetscInt *, PetscInt **, PetscScalar **);
PETSC_INTERN PetscErrorCode MatRestoreRow_MPIBinBCSR(Mat, PetscInt, PetscInt *, PetscInt **, PetscScalar **);
PETSC_INTERN PetscErrorCode MatNorm_MPIBinBCSR(Mat, NormType, PetscReal *);
PETSC_INTERN PetscErrorCode MatGetInfo_MPIBinBCSR(Mat, MatInfoType, MatInfo *);

/* mpibinbcsr_rowops.cpp: rows, columns and whole-matrix operations */
PETSC_INTERN PetscErrorCode MatDiagonalScale_MPIBinBCSR(Mat, Vec, Vec);
PETSC_INTERN PetscErrorCode MatGetRowMaxAbs_MPIBinBCSR(Mat, Vec, PetscInt[]);
PETSC_INTERN PetscErrorCode MatGetRowMax_MPIBinBCSR(Mat, Vec, PetscInt[]);
PETSC_INTERN PetscErrorCode MatGetRowMin_MPIBinBCSR(Mat, Vec, PetscInt[]);
PETSC_INTERN PetscErrorCode MatGetRowMinAbs_MPIBinBCSR(Mat, Vec, PetscInt[]);
PETSC_INTERN PetscErrorCode MatGetColumnReductions_MPIBinBCSR(Mat, PetscInt, PetscReal *);
PETSC_INTERN PetscErrorCode MatMissingDiagonal_MPIBinBCSR(Mat, PetscBool *, PetscInt *);
PETSC_INTERN PetscErrorCode MatEqual_MPIBinBCSR(Mat, Mat, PetscBool *);
PETSC_INTERN PetscErrorCode MatGetValues_MPIBinBCSR(Mat, PetscInt, const PetscInt[], PetscInt,
                                                    const PetscInt[], PetscScalar[]);
PETSC_INTERN PetscErrorCode MatAXPY_MPIBinBCSR(Mat, PetscScalar, Mat, MatStructure);
PETSC_INTERN PetscErrorCode MatTranspose_MPIBinBCSR(Mat, MatReuse, Mat *);

/* mpibinbcsr_rowij.cpp: the local rows' structure, global columns (MPIAIJ's MatGetRowIJ) */
PETSC_INTERN PetscErrorCode MatGetRowIJ_MPIBinBCSR(Mat, PetscInt, PetscBool, PetscBool, PetscInt *,
                                                   const PetscInt *[], const PetscInt *[], PetscBool *);
PETSC_INTERN PetscErrorCode MatRestoreRowIJ_MPIBinBCSR(Mat, PetscInt, PetscBool, PetscBool, PetscInt *,
                                                       const PetscInt *[], const PetscInt *[], PetscBool *);

/* mpibinbcsr_convert.cpp: conversion, load, view */
PETSC_INTERN PetscErrorCode MatConvert_MPIBinBCSR_MPIAIJ(Mat, MatType, MatReuse, Mat *);
PETSC_INTERN PetscErrorCode MatConvertFrom_MPIBinBCSR(Mat, MatType, MatReuse, Mat *);
PETSC_INTERN PetscErrorCode MatLoad_MPIBinBCSR(Mat, PetscViewer);
PETSC_INTERN PetscErrorCode MatView_MPIBinBCSR(Mat, PetscViewer);
PETSC_INTERN PetscErrorCode MatDuplicate_MPIBinBCSR(Mat, MatDuplicateOption, Mat *);
PETSC_INTERN PetscErrorCode MatCopy_MPIBinBCSR(Mat, Mat, MatStructure);

#endif
