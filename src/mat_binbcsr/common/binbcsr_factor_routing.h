/* Factorisations of a binbcsr matrix routed through a shadow: the factor Mat is a solver package's
   factor of a shadow copy S (a type the package factors), and its ops are wrapped so that each call
   first brings S up to date with the binbcsr matrix and then runs the package's routine with S in its
   place. One mechanism for PETSc's own factorisations (seq/binbcsr_factor.cpp: a blocked shadow kept by
   the factor) and the external packages' (binbcsr_factor_external.cpp: the matrix's AIJ shadow).

   Ctx, the routing's state composed on the factor, provides:
     static const char *key();                       the composition key
     static PetscErrorCode Destroy(void *);          frees a Ctx (and what it holds)
     PetscErrorCode Shadow(Mat A, Mat *S);           S holding A's current values
     PetscErrorCode Routed(Mat F);                   after each symbolic/numeric: the factor's ops set
     lunumeric, choleskynumeric                      the package's numeric ops (filled here) */
#ifndef BINBCSR_FACTOR_ROUTING_H
#define BINBCSR_FACTOR_ROUTING_H

#include <petsc/private/matimpl.h>
#include "binbcsr_composed.h"

namespace binbcsr_factor {

template <class Ctx> PetscErrorCode Attach(Mat F, Ctx *f)
{
  return binbcsr::Compose((PetscObject)F, Ctx::key(), f, Ctx::Destroy);
}

template <class Ctx> PetscErrorCode Get(Mat F, Ctx **f)
{
  PetscFunctionBegin;
  PetscCall(binbcsr::QueryComposed((PetscObject)F, Ctx::key(), f));
  PetscCheck(*f, PETSC_COMM_SELF, PETSC_ERR_PLIB, "Factor of a binbcsr matrix without its routing (%s)",
             Ctx::key());
  PetscFunctionReturn(0);
}

template <class Ctx> PetscErrorCode LUNumeric(Mat, Mat, const MatFactorInfo *);
template <class Ctx> PetscErrorCode CholeskyNumeric(Mat, Mat, const MatFactorInfo *);

/* A package's symbolic (or numeric) routine chooses its numeric one: route that through the shadow too. */
template <class Ctx> void RouteNumeric(Mat F, Ctx *f)
{
  if (F->ops->lufactornumeric && F->ops->lufactornumeric != LUNumeric<Ctx>) {
    f->lunumeric            = F->ops->lufactornumeric;
    F->ops->lufactornumeric = LUNumeric<Ctx>;
  }
  if (F->ops->choleskyfactornumeric && F->ops->choleskyfactornumeric != CholeskyNumeric<Ctx>) {
    f->choleskynumeric            = F->ops->choleskyfactornumeric;
    F->ops->choleskyfactornumeric = CholeskyNumeric<Ctx>;
  }
}

/* Bring the shadow of A up to date, run routine(f, S), keep the numeric routed. */
template <class Ctx, class Routine> PetscErrorCode OnShadow(Mat F, Mat A, Routine &&routine)
{
  Ctx *f;
  Mat  S;

  PetscFunctionBegin;
  PetscCall(Get(F, &f));
  PetscCall(f->Shadow(A, &S));
  PetscCall(routine(f, S));
  RouteNumeric(F, f);
  PetscCall(f->Routed(F));
  PetscFunctionReturn(0);
}

template <class Ctx> PetscErrorCode LUNumeric(Mat F, Mat A, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(OnShadow<Ctx>(F, A, [&](Ctx *f, Mat S) { return (*f->lunumeric)(F, S, info); }));
  PetscFunctionReturn(0);
}

template <class Ctx> PetscErrorCode CholeskyNumeric(Mat F, Mat A, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(OnShadow<Ctx>(F, A, [&](Ctx *f, Mat S) { return (*f->choleskynumeric)(F, S, info); }));
  PetscFunctionReturn(0);
}

} // namespace binbcsr_factor

#endif
