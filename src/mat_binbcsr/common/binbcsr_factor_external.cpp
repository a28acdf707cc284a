/* Direct solvers of other packages (MUMPS, SuperLU_DIST) for MATSEQBINBCSR and MATMPIBINBCSR, so that
   -pc_type lu / cholesky work on any number of ranks as they do with aij.

   These packages take their input as AIJ (triples or compressed rows), so the factor is the package's
   own factor of the matrix's AIJ shadow (the one its submatrices use, binbcsr_submat.cpp): MatGetFactor
   asks the shadow for the package's factor Mat and wraps its symbolic and numeric ops, which then
   refresh the shadow from the binbcsr matrix (values only, when only they changed) and call the
   package's routine with the shadow in place of the binbcsr matrix (binbcsr_factor_routing.h, shared
   with PETSc's own factorisations of MATSEQBINBCSR, seq/binbcsr_factor.cpp, which keep a blocked shadow
   instead). Solves are the factor's own. */
#include "binbcsr_impl.h"
#include "binbcsr_factor_routing.h"

namespace {
struct ExternalFactor {
  /* the package's ops of the factor, called with the shadow in place of the binbcsr matrix */
  PetscErrorCode (*lusymbolic)(Mat, Mat, IS, IS, const MatFactorInfo *)   = nullptr;
  PetscErrorCode (*choleskysymbolic)(Mat, Mat, IS, const MatFactorInfo *) = nullptr;
  PetscErrorCode (*lunumeric)(Mat, Mat, const MatFactorInfo *)            = nullptr;
  PetscErrorCode (*choleskynumeric)(Mat, Mat, const MatFactorInfo *)      = nullptr;

  static const char    *key() { return "MatBinBCSR_ExternalFactor"; }
  static PetscErrorCode Destroy(void *ctx)
  {
    PetscFunctionBegin;
    delete static_cast<ExternalFactor *>(ctx);
    PetscFunctionReturn(0);
  }
  PetscErrorCode Shadow(Mat A, Mat *S) { return MatBinBCSRGetAIJShadow_Private(A, S); }
  PetscErrorCode Routed(Mat) { return 0; } /* the package's solves as they are */
};

PetscErrorCode LUSymbolic(Mat F, Mat A, IS r, IS c, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(binbcsr_factor::OnShadow<ExternalFactor>(
    F, A, [&](ExternalFactor *f, Mat S) { return (*f->lusymbolic)(F, S, r, c, info); }));
  PetscFunctionReturn(0);
}

PetscErrorCode CholeskySymbolic(Mat F, Mat A, IS r, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(binbcsr_factor::OnShadow<ExternalFactor>(
    F, A, [&](ExternalFactor *f, Mat S) { return (*f->choleskysymbolic)(F, S, r, info); }));
  PetscFunctionReturn(0);
}

PetscErrorCode GetFactorFrom(Mat A, MatSolverType package, MatFactorType ftype, Mat *F)
{
  Mat             S;
  ExternalFactor *f;

  PetscFunctionBegin;
  if (A->assembled) PetscCall(MatBinBCSRGetAIJShadow_Private(A, &S));
  else { /* PCSetFromOptions asks for the factor before the values exist (ts ex2): the package's
            factor of an empty AIJ matrix of A's layout; the symbolic phase gets the real shadow */
    PetscMPIInt size;
    PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)A), &size));
    PetscCall(MatCreate(PetscObjectComm((PetscObject)A), &S));
    PetscCall(MatSetLayouts(S, A->rmap, A->cmap));
    PetscCall(MatSetType(S, size > 1 ? MATMPIAIJ : MATSEQAIJ));
    PetscCall(MatSetUp(S));
    PetscCall(MatPropagateSymmetryOptions(A, S));
  }
  PetscCall(MatGetFactor(S, package, ftype, F));
  PetscCheck(*F, PetscObjectComm((PetscObject)A), PETSC_ERR_SUP, "%s has no %s factorisation of %s", package,
             MatFactorTypes[ftype], ((PetscObject)S)->type_name);
  if (!A->assembled) PetscCall(MatDestroy(&S));
  f = new ExternalFactor;
  PetscCall(binbcsr_factor::Attach(*F, f));
  f->lusymbolic       = (*F)->ops->lufactorsymbolic;
  f->choleskysymbolic = (*F)->ops->choleskyfactorsymbolic;
  if (f->lusymbolic) (*F)->ops->lufactorsymbolic = LUSymbolic;
  if (f->choleskysymbolic) (*F)->ops->choleskyfactorsymbolic = CholeskySymbolic;
  binbcsr_factor::RouteNumeric(*F, f);
  PetscFunctionReturn(0);
}

/* MatSolverTypeRegister's factories are not told the package: one instance per package. */
template <const char *package> PetscErrorCode GetFactor(Mat A, MatFactorType ftype, Mat *F)
{
  PetscFunctionBegin;
  PetscCall(GetFactorFrom(A, package, ftype, F));
  PetscFunctionReturn(0);
}
#if defined(PETSC_HAVE_MUMPS)
constexpr char mumps[] = MATSOLVERMUMPS;
#endif
#if defined(PETSC_HAVE_SUPERLU_DIST)
constexpr char superlu_dist[] = MATSOLVERSUPERLU_DIST;
#endif
} // namespace

/* After MATSOLVERPETSC's registration, so that PETSc's own stays the default on one rank (MUMPS is
   the default on more, as for aij). */
PetscErrorCode MatBinBCSRRegisterExternalFactors(void)
{
  PetscFunctionBegin;
  for (MatType type : {MATSEQBINBCSR, MATMPIBINBCSR}) {
#if defined(PETSC_HAVE_MUMPS)
    PetscCall(MatSolverTypeRegister(MATSOLVERMUMPS, type, MAT_FACTOR_LU, GetFactor<mumps>));
    PetscCall(MatSolverTypeRegister(MATSOLVERMUMPS, type, MAT_FACTOR_CHOLESKY, GetFactor<mumps>));
#endif
#if defined(PETSC_HAVE_SUPERLU_DIST)
    PetscCall(MatSolverTypeRegister(MATSOLVERSUPERLU_DIST, type, MAT_FACTOR_LU, GetFactor<superlu_dist>));
#endif
    (void)type;
  }
  PetscFunctionReturn(0);
}
