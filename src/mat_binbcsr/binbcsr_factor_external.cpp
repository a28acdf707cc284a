/* Direct solvers of other packages (MUMPS, SuperLU_DIST) for MATSEQBINBCSR and MATMPIBINBCSR, so that
   -pc_type lu / cholesky work on any number of ranks as they do with aij.

   These packages take their input as AIJ (triples or compressed rows), so the factor is the package's
   own factor of the matrix's AIJ shadow (the one its submatrices use, binbcsr_submat.cpp): MatGetFactor
   asks the shadow for the package's factor Mat and wraps its symbolic and numeric ops, which then
   refresh the shadow from the binbcsr matrix (values only, when only they changed) and call the
   package's routine with the shadow in place of the binbcsr matrix. Solves are the factor's own. The
   same routing as PETSc's own factorisations of MATSEQBINBCSR (seq/binbcsr_factor.cpp), which keep a
   blocked shadow instead. */
#include "binbcsr_impl.h"
#include <petsc/private/matimpl.h>

namespace
{
struct ExternalFactor {
  /* the package's ops of the factor, called with the shadow in place of the binbcsr matrix */
  PetscErrorCode (*lusymbolic)(Mat, Mat, IS, IS, const MatFactorInfo *)      = nullptr;
  PetscErrorCode (*choleskysymbolic)(Mat, Mat, IS, const MatFactorInfo *)    = nullptr;
  PetscErrorCode (*lunumeric)(Mat, Mat, const MatFactorInfo *)               = nullptr;
  PetscErrorCode (*choleskynumeric)(Mat, Mat, const MatFactorInfo *)         = nullptr;
};

const char factor_key[] = "MatBinBCSR_ExternalFactor";

PetscErrorCode DestroyExternalFactor(void *ctx)
{
  PetscFunctionBegin;
  delete static_cast<ExternalFactor *>(ctx);
  PetscFunctionReturn(0);
}

PetscErrorCode GetExternalFactor(Mat F, ExternalFactor **f)
{
  PetscContainer c;

  PetscFunctionBegin;
  PetscCall(PetscObjectQuery((PetscObject)F, factor_key, (PetscObject *)&c));
  PetscCheck(c, PETSC_COMM_SELF, PETSC_ERR_PLIB, "Factor of a binbcsr matrix without its routing");
  PetscCall(PetscContainerGetPointer(c, (void **)f));
  PetscFunctionReturn(0);
}

PetscErrorCode LUNumeric(Mat, Mat, const MatFactorInfo *);
PetscErrorCode CholeskyNumeric(Mat, Mat, const MatFactorInfo *);

/* The package's symbolic routine chooses its numeric one: route that through the shadow too. */
void WrapNumeric(Mat F, ExternalFactor *f)
{
  if (F->ops->lufactornumeric && F->ops->lufactornumeric != LUNumeric) {
    f->lunumeric            = F->ops->lufactornumeric;
    F->ops->lufactornumeric = LUNumeric;
  }
  if (F->ops->choleskyfactornumeric && F->ops->choleskyfactornumeric != CholeskyNumeric) {
    f->choleskynumeric            = F->ops->choleskyfactornumeric;
    F->ops->choleskyfactornumeric = CholeskyNumeric;
  }
}

/* Refresh the shadow of A, run the package's routine on it, keep the numeric routed. */
template <class Routine>
PetscErrorCode OnShadow(Mat F, Mat A, Routine &&routine)
{
  ExternalFactor *f;
  Mat             S;

  PetscFunctionBegin;
  PetscCall(GetExternalFactor(F, &f));
  PetscCall(MatBinBCSRGetAIJShadow_Private(A, &S));
  PetscCall(routine(f, S));
  WrapNumeric(F, f);
  PetscFunctionReturn(0);
}

PetscErrorCode LUSymbolic(Mat F, Mat A, IS r, IS c, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(OnShadow(F, A, [&](ExternalFactor *f, Mat S) { return (*f->lusymbolic)(F, S, r, c, info); }));
  PetscFunctionReturn(0);
}

PetscErrorCode CholeskySymbolic(Mat F, Mat A, IS r, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(OnShadow(F, A, [&](ExternalFactor *f, Mat S) { return (*f->choleskysymbolic)(F, S, r, info); }));
  PetscFunctionReturn(0);
}

PetscErrorCode LUNumeric(Mat F, Mat A, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(OnShadow(F, A, [&](ExternalFactor *f, Mat S) { return (*f->lunumeric)(F, S, info); }));
  PetscFunctionReturn(0);
}

PetscErrorCode CholeskyNumeric(Mat F, Mat A, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(OnShadow(F, A, [&](ExternalFactor *f, Mat S) { return (*f->choleskynumeric)(F, S, info); }));
  PetscFunctionReturn(0);
}

PetscErrorCode GetFactorFrom(Mat A, MatSolverType package, MatFactorType ftype, Mat *F)
{
  Mat             S;
  ExternalFactor *f;
  PetscContainer  c;

  PetscFunctionBegin;
  PetscCall(MatBinBCSRGetAIJShadow_Private(A, &S));
  PetscCall(MatGetFactor(S, package, ftype, F));
  PetscCheck(*F, PetscObjectComm((PetscObject)A), PETSC_ERR_SUP, "%s has no %s factorisation of %s", package, MatFactorTypes[ftype], ((PetscObject)S)->type_name);
  f = new ExternalFactor;
  PetscCall(PetscContainerCreate(PETSC_COMM_SELF, &c));
  PetscCall(PetscContainerSetPointer(c, f));
  PetscCall(PetscContainerSetUserDestroy(c, DestroyExternalFactor));
  PetscCall(PetscObjectCompose((PetscObject)*F, factor_key, (PetscObject)c));
  PetscCall(PetscContainerDestroy(&c));
  f->lusymbolic       = (*F)->ops->lufactorsymbolic;
  f->choleskysymbolic = (*F)->ops->choleskyfactorsymbolic;
  if (f->lusymbolic) (*F)->ops->lufactorsymbolic = LUSymbolic;
  if (f->choleskysymbolic) (*F)->ops->choleskyfactorsymbolic = CholeskySymbolic;
  WrapNumeric(*F, f);
  PetscFunctionReturn(0);
}

/* MatSolverTypeRegister's factories are not told the package: one per package. */
#if defined(PETSC_HAVE_MUMPS)
PetscErrorCode GetFactor_MUMPS(Mat A, MatFactorType ftype, Mat *F)
{
  PetscFunctionBegin;
  PetscCall(GetFactorFrom(A, MATSOLVERMUMPS, ftype, F));
  PetscFunctionReturn(0);
}
#endif
#if defined(PETSC_HAVE_SUPERLU_DIST)
PetscErrorCode GetFactor_SuperLU_DIST(Mat A, MatFactorType ftype, Mat *F)
{
  PetscFunctionBegin;
  PetscCall(GetFactorFrom(A, MATSOLVERSUPERLU_DIST, ftype, F));
  PetscFunctionReturn(0);
}
#endif
} // namespace

/* After MATSOLVERPETSC's registration, so that PETSc's own stays the default on one rank (MUMPS is
   the default on more, as for aij). */
PetscErrorCode MatBinBCSRRegisterExternalFactors(void)
{
  PetscFunctionBegin;
  for (MatType type : {MATSEQBINBCSR, MATMPIBINBCSR}) {
#if defined(PETSC_HAVE_MUMPS)
    PetscCall(MatSolverTypeRegister(MATSOLVERMUMPS, type, MAT_FACTOR_LU, GetFactor_MUMPS));
    PetscCall(MatSolverTypeRegister(MATSOLVERMUMPS, type, MAT_FACTOR_CHOLESKY, GetFactor_MUMPS));
#endif
#if defined(PETSC_HAVE_SUPERLU_DIST)
    PetscCall(MatSolverTypeRegister(MATSOLVERSUPERLU_DIST, type, MAT_FACTOR_LU, GetFactor_SuperLU_DIST));
#endif
    (void)type;
  }
  PetscFunctionReturn(0);
}
