/* MatBinBCSRSetKernel / GetKernel and the -mat_binbcsr_kernel option: the PETSc face of the body sets
   of src/mat_binbcsr/kernels/ (binbcsr_dispatch.h). The choice itself is select_body's. */
#include "../seq/binbcsr.h"
#include "../mpi/mpibinbcsr.h"

const char *const MatBinBCSRKernels[] = {
  "auto", "portable", "avx2", "avx512", "MatBinBCSRKernel", "MAT_BINBCSR_KERNEL_", nullptr};

PetscErrorCode MatBinBCSRKernelAvailable(MatBinBCSRKernel kernel, PetscBool *avail)
{
  PetscFunctionBegin;
  PetscAssertPointer(avail, 2);
  *avail = (kernel >= MAT_BINBCSR_KERNEL_AUTO && kernel <= MAT_BINBCSR_KERNEL_AVX512 &&
            binbcsr::body_set_available((binbcsr::BodySet)kernel))
             ? PETSC_TRUE
             : PETSC_FALSE;
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRSetKernel(Mat A, MatBinBCSRKernel kernel)
{
  PetscBool seq, mpi, avail;

  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidLogicalCollectiveEnum(A, kernel, 2);
  PetscCheck(kernel >= MAT_BINBCSR_KERNEL_AUTO && kernel <= MAT_BINBCSR_KERNEL_AVX512,
             PetscObjectComm((PetscObject)A), PETSC_ERR_ARG_OUTOFRANGE,
             "Unknown MatBinBCSRKernel %d: use auto, portable, avx2 or avx512", (int)kernel);
  PetscCall(MatBinBCSRKernelAvailable(kernel, &avail));
  PetscCheck(
    avail, PETSC_COMM_SELF, PETSC_ERR_SUP_SYS,
    "MATBINBCSR kernel %s: this CPU (or this build of the library) lacks it; available: portable%s%s",
    MatBinBCSRKernels[kernel], binbcsr::body_set_available(binbcsr::BodySet::AVX2) ? ", avx2" : "",
    binbcsr::body_set_available(binbcsr::BodySet::AVX512) ? ", avx512" : "");
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATSEQBINBCSR, &seq));
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIBINBCSR, &mpi));
  if (seq) ((Mat_SeqBinBCSR *)A->data)->kernel = kernel;
  else if (mpi) {
    Mat_MPIBinBCSR *b = MPIBinBCSR(A);
    b->kernel         = kernel;
    if (b->A) PetscCall(MatBinBCSRSetKernel(b->A, kernel));
    if (b->B) PetscCall(MatBinBCSRSetKernel(b->B, kernel));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetKernel(Mat A, MatBinBCSRKernel *kernel)
{
  PetscBool seq, mpi;

  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscAssertPointer(kernel, 2);
  *kernel = MAT_BINBCSR_KERNEL_PORTABLE;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATSEQBINBCSR, &seq));
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIBINBCSR, &mpi));
  if (seq) *kernel = (MatBinBCSRKernel)MatSeqBinBCSRSelectBody((Mat_SeqBinBCSR *)A->data).set;
  else if (mpi) {
    Mat_MPIBinBCSR *b = MPIBinBCSR(A);
    if (b->A) PetscCall(MatBinBCSRGetKernel(b->A, kernel)); /* the diagonal part: the bulk of the work */
    else
      *kernel = (MatBinBCSRKernel)binbcsr::select_body(
                  {A->rmap->bs, b->bin_width ? (int)b->bin_width : (int)BinBCSRDefaultBinWidth(A->rmap->bs),
                   b->streams ? (int)b->streams : BINBCSR_DEFAULT_STREAMS,
                   b->precision == MAT_BINBCSR_PRECISION_SINGLE, b->sym ? true : false},
                  (binbcsr::BodySet)b->kernel)
                  .set;
  }
  PetscFunctionReturn(0);
}
