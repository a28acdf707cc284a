/* The differences between the PETSc versions the plug-in supports (3.18 to 3.22), in one place, so
   that the rest of the code is written once against the newest interface. Each entry names the
   version that changed it (3.18 and 3.22 are the ones built and tested). */
#ifndef BINBCSR_PETSC_COMPAT_H
#define BINBCSR_PETSC_COMPAT_H

#include <petscversion.h>
#include <petscmat.h>
#include <petscvec.h>
#include <petscviewer.h>

/* MatCreateGraph and its MatOps slot: 3.21 added the index set of the diagonal entries to filter
   by (num_idx, index[]). BINBCSR_CREATEGRAPH_ARGS declares the parameters after `filter`,
   BINBCSR_CREATEGRAPH_PASS hands them on, BINBCSR_CREATEGRAPH_NO_INDEX passes none,
   BINBCSR_CREATEGRAPH_WHOLE_BLOCKS continues a condition with "no index set given". */
#if PETSC_VERSION_GE(3, 21, 0)
  #define BINBCSR_CREATEGRAPH_ARGS     , PetscInt num_idx, PetscInt index[]
  #define BINBCSR_CREATEGRAPH_PASS     , num_idx, index
  #define BINBCSR_CREATEGRAPH_TYPES    , PetscInt, PetscInt[]
  #define BINBCSR_CREATEGRAPH_NO_INDEX , 0, nullptr
  /* the block graph sums whole blocks: only without an index set */
  #define BINBCSR_CREATEGRAPH_WHOLE_BLOCKS &&num_idx <= 0
#else
  #define BINBCSR_CREATEGRAPH_WHOLE_BLOCKS
  #define BINBCSR_CREATEGRAPH_ARGS
  #define BINBCSR_CREATEGRAPH_PASS
  #define BINBCSR_CREATEGRAPH_TYPES
  #define BINBCSR_CREATEGRAPH_NO_INDEX
#endif

/* Marks a vector as holding the result of a failed operation (Inf): 3.22 replaced VecSetInf by
   VecFlag (and declares the deprecated VecSetInf without C linkage, so C++ cannot link it). */
#if PETSC_VERSION_GE(3, 22, 0)
  #define BinBCSRVecSetInf(v) VecFlag((v), 1)
#else
  #define BinBCSRVecSetInf(v) VecSetInf(v)
#endif

/* 3.21 renamed PCGetFailedReasonRank (this rank's reason) to PCGetFailedReason, whose old collective
   form became PCReduceFailedReason + PCGetFailedReason. */
#if PETSC_VERSION_GE(3, 21, 0)
  #define PCGetFailedReasonRank PCGetFailedReason
#endif

/* 3.22 renamed PetscOptionsGetViewer (the viewer is destroyed with PetscViewerDestroy in both). */
#if PETSC_VERSION_LT(3, 22, 0)
  #define PetscOptionsCreateViewer PetscOptionsGetViewer
#endif

/* 3.22 renamed PetscOptionsPushGetViewerOff and PetscOptionsPopGetViewerOff (the -xxx_view options
   switched off for internal objects). */
#if PETSC_VERSION_LT(3, 22, 0)
  #define PetscOptionsPushCreateViewerOff PetscOptionsPushGetViewerOff
  #define PetscOptionsPopCreateViewerOff  PetscOptionsPopGetViewerOff
#endif

/* 3.20 replaced PetscValidPointer (argument checks, petsc/private/petscimpl.h) by PetscAssertPointer. */
#if PETSC_VERSION_LT(3, 20, 0)
  #define PetscAssertPointer(h, arg) PetscValidPointer(h, arg)
#endif

#endif
