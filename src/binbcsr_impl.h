/* Private declarations shared by the parts of the plug-in: constructors that the registration
   calls and the -log_view events of the hot kernels. */
#ifndef BINBCSR_IMPL_H
#define BINBCSR_IMPL_H

/* Default MatBinBCSRSetStreams (seq and mpi): 4 runs of bins swept side by side (docs/mat_binbcsr.md:
   on the 48^3 stencil 2, 4, 6 and 8 runs all beat 1; 4 was the fastest or within the noise of it). */
#define BINBCSR_DEFAULT_STREAMS 4
/* Default MatBinBCSRSetPrefetch: values prefetched 4 KiB ahead (chosen on a Sapphire Rapids core; the
   tuner times 0, 1 and 4 KiB where it is not set, docs/tuning.md). */
#define BINBCSR_DEFAULT_PREFETCH 4096

#include <petscbinbcsr.h>
#include <petsc/private/petscimpl.h>
#include "petsc_compat.h"

PETSC_EXTERN PetscErrorCode MatCreate_SeqBinBCSR(Mat);
PETSC_EXTERN PetscErrorCode MatCreate_MPIBinBCSR(Mat);
PETSC_EXTERN PetscErrorCode KSPCreate_MCG(KSP);
/* ICC, Cholesky (through seqsbaij), ILU, LU (through seqbaij) for MATSOLVERPETSC: seq/binbcsr_factor.cpp */
PETSC_INTERN PetscErrorCode MatGetFactor_SeqBinBCSR_Petsc(Mat, MatFactorType, Mat *);

/* Inserts src's local rows into dst (INSERT_VALUES) and assembles dst: the generic conversion path. */
PETSC_INTERN PetscErrorCode MatBinBCSRInsertRows_Private(Mat src, Mat dst);
/* Preallocates dst (sized and typed, answering the AIJ preallocations) exactly from src's local rows, then fills it. */
PETSC_INTERN PetscErrorCode MatBinBCSRPreallocateAndFill_Private(Mat src, Mat dst);
/* An empty matrix of the given type with src's sizes and block sizes: a conversion's target (seq and mpi). */
PETSC_INTERN PetscErrorCode MatBinBCSRCreateLike_Private(Mat src, MatType type, Mat *M);

/* Submatrices (PCASM, PCGASM, PCREDUNDANT, PCFIELDSPLIT) of seq and mpi binbcsr through an AIJ shadow: common/binbcsr_submat.cpp */
PETSC_INTERN PetscErrorCode MatIncreaseOverlap_BinBCSR(Mat, PetscInt, IS[], PetscInt);
PETSC_INTERN PetscErrorCode MatCreateSubMatrices_BinBCSR(Mat, PetscInt, const IS[], const IS[], MatReuse,
                                                         Mat *[]);
PETSC_INTERN PetscErrorCode MatCreateSubMatricesMPI_BinBCSR(Mat, PetscInt, const IS[], const IS[], MatReuse,
                                                            Mat *[]);
PETSC_INTERN PetscErrorCode MatCreateSubMatrix_BinBCSR(Mat, IS, IS, MatReuse, Mat *);
PETSC_INTERN PetscErrorCode MatCreateMPIMatConcatenateSeqMat_BinBCSR(MPI_Comm, Mat, PetscInt, MatReuse,
                                                                     Mat *);
PETSC_INTERN PetscErrorCode MatConvert_BinBCSR_HYPRE(Mat, MatType, MatReuse,
                                                     Mat *); /* composed as MatConvert_<type>_hypre_C */
/* The seqaij/mpiaij copy of a binbcsr matrix, composed on it, refreshed when the matrix changed (collective) */
PETSC_INTERN PetscErrorCode MatBinBCSRGetAIJShadow_Private(Mat, Mat *);
/* and back: the shadow's values written into the matrix (both then in step) */
PETSC_INTERN PetscErrorCode MatBinBCSRSetValuesFromAIJShadow_Private(Mat);
/* Finite-difference Jacobians by colouring (MatFDColoring, SNES's default with a DMDA) through that shadow: common/binbcsr_fdcoloring.cpp */
PETSC_INTERN PetscErrorCode MatFDColoringCreate_BinBCSR(Mat, ISColoring, MatFDColoring);
PETSC_INTERN PetscErrorCode MatFDColoringSetUp_BinBCSR(Mat, ISColoring, MatFDColoring);
PETSC_INTERN PetscErrorCode MatFDColoringApply_BinBCSR(Mat, MatFDColoring, Vec, void *);
/* PCGAMG's needs through that shadow (MatCreateGraph, matrix products with binbcsr operands): common/binbcsr_shadow_ops.cpp */
/* C = P^T A P of a MATSEQBINBCSR A and a SeqAIJ P, A P made from the blocks (seq/binbcsr_ptap.cpp) */
PETSC_INTERN PetscErrorCode MatProductSymbolic_PtAP_SeqBinBCSR_SeqAIJ(Mat);
/* MATSEQBINBCSR's block graph (seq/binbcsr_graph.cpp): block size 1, one weight per stored block */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRBlockGraph(Mat, Mat *);
PETSC_INTERN PetscErrorCode MatCreateGraph_BinBCSR(Mat, PetscBool, PetscBool,
                                                   PetscReal BINBCSR_CREATEGRAPH_TYPES, Mat *);
PETSC_INTERN PetscErrorCode
  MatProductSetFromOptions_BinBCSR(Mat); /* also composed as MatProductSetFromOptions_anytype_C */
/* MUMPS / SuperLU_DIST LU and Cholesky for seq and mpi binbcsr through that shadow: common/binbcsr_factor_external.cpp */
PETSC_INTERN PetscErrorCode MatBinBCSRRegisterExternalFactors(void);

/* MATSEQBINBCSR parts of MATMPIBINBCSR: after MatSetPreallocationCOO, compose the part's COO map with
   from[] (part entry -> source index); the two-source refill then reads source p < n from v and
   p >= n from recv[p - n], and leaves the part to be assembled by the caller. A plain MatSetValuesCOO
   on the part keeps its own map. */
PETSC_INTERN PetscErrorCode
                            MatSeqBinBCSRComposeCOO(Mat, const PetscCount from[], PetscCount n,
                                                    PetscCount nsrc); /* from[] < n: the caller's values, else received */
PETSC_INTERN PetscErrorCode MatSetValuesCOOTwoSources_SeqBinBCSR(Mat, const PetscScalar v[], PetscCount n,
                                                                 const PetscScalar recv[], InsertMode);
/* the same with the caller's values in single precision (MatBinBCSRSetValuesCOOSingle) */
PETSC_INTERN PetscErrorCode MatSetValuesCOOTwoSourcesSingle_SeqBinBCSR(Mat, const float v[], PetscCount n,
                                                                       const PetscScalar recv[], InsertMode);

/* An empty, set-up matrix of A's binbcsr type and configuration (bin width, precision, storage, MPI inner
   type) with the given local sizes and block sizes; and the MatAXPY_Basic hook built on it, composed as
   "MatAXPYGetPreallocation_C" (common/binbcsr_permute.cpp) */
PETSC_INTERN PetscErrorCode MatBinBCSRCreateEmptyLike_Private(Mat A, PetscInt m, PetscInt n, PetscInt rbs,
                                                              PetscInt cbs, Mat *C);
PETSC_INTERN PetscErrorCode MatAXPYGetPreallocation_BinBCSR(Mat Y, Mat X, Mat *B);
/* MatPermute of seq and mpi binbcsr: a new matrix of the same type and configuration (common/binbcsr_permute.cpp) */
PETSC_INTERN PetscErrorCode MatPermute_BinBCSR(Mat, IS, IS, Mat *);
/* MatIsSymmetric (through the transpose), MatFindZeroDiagonals, MatFindNonzeroRows of seq and mpi binbcsr (common/binbcsr_queries.cpp) */
PETSC_INTERN PetscErrorCode MatIsSymmetric_BinBCSR(Mat, PetscReal, PetscBool *);
PETSC_INTERN PetscErrorCode MatFindZeroDiagonals_BinBCSR(Mat, IS *);
PETSC_INTERN PetscErrorCode MatFindNonzeroRows_BinBCSR(Mat, IS *);
/* MatSetRandom (the stored pattern), MatRealPart, MatImaginaryPart of seq and mpi binbcsr (common/binbcsr_value_fill.cpp) */
PETSC_INTERN PetscErrorCode MatSetRandom_BinBCSR(Mat, PetscRandom);
PETSC_INTERN PetscErrorCode MatRealPart_BinBCSR(Mat);
PETSC_INTERN PetscErrorCode MatImaginaryPart_BinBCSR(Mat);

/* The -mat_binbcsr_* options (one list for seq and mpi), read inside a type's MatSetFromOptions and
   applied through the public setters: common/binbcsr_options.cpp */
PETSC_INTERN PetscErrorCode MatBinBCSRReadOptions_Private(Mat, PetscOptionItems *);

/* The whole of a public setter or getter that only validates its arguments and calls the composed
   "<Name>_C" of the object's actual type, doing nothing (setter) or leaving the documented default
   (getter) on other types: each such function is one line under its manual page. A macro, not a helper
   function, so that the argument checks and PETSc's traceback still name the public function. valid is
   PETSc's check for the value: PetscValidLogicalCollective{Int,Bool,Enum} (setter),
   PetscValid{Int,Bool,}Pointer (getter). */
#define BINBCSR_TRY_SETTER(Name, Obj, classid, T, valid) \
  PetscErrorCode Name(Obj obj, T v)                      \
  {                                                      \
    PetscFunctionBegin;                                  \
    PetscValidHeaderSpecific(obj, classid, 1);           \
    valid(obj, v, 2);                                    \
    PetscTryMethod(obj, #Name "_C", (Obj, T), (obj, v)); \
    PetscFunctionReturn(0);                              \
  }
#define BINBCSR_TRY_GETTER(Name, Obj, classid, T, valid, dflt) \
  PetscErrorCode Name(Obj obj, T *v)                           \
  {                                                            \
    PetscFunctionBegin;                                        \
    PetscValidHeaderSpecific(obj, classid, 1);                 \
    valid(v, 2);                                               \
    *v = dflt;                                                 \
    PetscTryMethod(obj, #Name "_C", (Obj, T *), (obj, v));     \
    PetscFunctionReturn(0);                                    \
  }

/* *xdoty = the local part of x.y (no reduction), flops logged: the fallback of MatMultDotLocal and
   KSPMCG's transposed solve (interface/binbcsr_mult_dot.cpp) */
PETSC_INTERN PetscErrorCode MatBinBCSRVecDotLocal_Private(Vec x, Vec y, PetscScalar *xdoty);

/* A clear error unless v has n local entries (what: the argument's name in the message):
   interface/binbcsr_mult_dot.cpp */
PETSC_INTERN PetscErrorCode MatBinBCSRCheckVecLocalSize(Vec v, PetscInt n, const char *what);

/* Registered once by PetscBinBCSRRegisterAll(). */
PETSC_EXTERN PetscLogEvent MAT_BinBCSR_BuildLayout;  /* first final assembly: staging -> bins */
PETSC_EXTERN PetscLogEvent MAT_BinBCSR_SetValuesCOO; /* slot refill by gather */
PETSC_EXTERN PetscLogEvent MAT_BinBCSR_Tune;         /* the layout tuner (timing a sample's products) */
PETSC_EXTERN PetscLogEvent MAT_BinBCSR_MultDot;      /* y = A x fused with x.y */
PETSC_EXTERN PetscLogEvent KSP_MCG_FusedUpdate;      /* x, r, z (Jacobi), p, s updates + local dots */
PETSC_EXTERN PetscLogEvent KSP_MCG_Reduction;        /* the one global reduction per iteration */
PETSC_EXTERN PetscLogEvent
  MAT_BinBCSR_DeviceMult; /* MatMult of a device matrix on host vectors (copies in and out) */
PETSC_EXTERN PetscLogEvent
  MAT_BinBCSR_DeviceUpload; /* values to the device: whole array, or COO values + gather */
PETSC_EXTERN PetscLogEvent KSP_MCG_DeviceSolve; /* a KSPMCG solve run on the device */

#endif
