/* The device copy of a MATSEQBINBCSR (binbcsr_device.cpp): what KSPMCG's device solve
   (src/ksp_mcg/mcg_device_solve.cpp) needs of it. */
#ifndef BINBCSR_SEQ_DEVICE_H
#define BINBCSR_SEQ_DEVICE_H

#include "binbcsr.h"
#include "device/device.h"

/* The device matrix and its executor with values up to date (uploaded if the host values changed
   since), or nullptr when A has no device copy (any other type, or device none). */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRGetDeviceMatrix(Mat A, binbcsr::device::Executor **E,
                                                         binbcsr::device::Matrix **M);
/* A device vector of A's size holding v's values, cached on A under `slot` (0, 1, ...) and uploaded
   only when v's id or state changed; v = NULL: a work vector of A's row size, kept, never uploaded (the
   device solve's x: the same device arrays every solve keep its captured CUDA graphs valid). */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRDeviceCachedVector(Mat A, int slot, Vec v,
                                                            binbcsr::device::Vector **dv);

/* Turns a device library exception into a PETSc error. */
#define BinBCSRDeviceTry(expr)                                                  \
  do {                                                                          \
    try {                                                                       \
      expr;                                                                     \
    } catch (const std::exception &e_) {                                        \
      SETERRQ(PETSC_COMM_SELF, PETSC_ERR_LIB, "binbcsr device: %s", e_.what()); \
    }                                                                           \
  } while (0)

#endif
