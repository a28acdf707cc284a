/* KSPMCG's device solve (mcg_device_solve.cpp), called from KSPSolve_MCG once the path and the Jacobi
   diagonal are decided. */
#ifndef BINBCSR_MCG_DEVICE_SOLVE_H
#define BINBCSR_MCG_DEVICE_SOLVE_H
#include "mcg_impl.h"
/* *done: the solve ran on the device (Amat has a device copy and the solve is one the device does). */
PETSC_INTERN PetscErrorCode KSPSolve_MCG_Device(KSP ksp, Mat Amat, Mat Pmat, PetscBool *done);
#endif
