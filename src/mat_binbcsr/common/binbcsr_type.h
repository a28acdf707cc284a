/* What the constructors of both binbcsr types (seq/binbcsr.cpp, mpi/mpibinbcsr.cpp) share.

   The composed functions of a type come from ONE list: MatCreate composes every entry of the type's
   list and MatDestroy clears the same entries, so a name cannot be composed and left behind when the
   matrix changes type (MatConvert in place, MatSetType again).

   The ops both tables hold, implemented once for seq and mpi in common/, are named once here. */
#ifndef BINBCSR_TYPE_H
#define BINBCSR_TYPE_H

#include "binbcsr_impl.h"
#include <petsc/private/matimpl.h>
#include <cstddef>

/* PETSc stores every composed function as void (*)(void); its name says the signature. */
typedef void (*BinBCSRComposedFn)(void);

struct BinBCSRComposed {
  const char       *name; /* "MatBinBCSRSetBinWidth_C", ... */
  BinBCSRComposedFn fn;
};

/* One entry of a list: BINBCSR_COMPOSED("MatBinBCSRSetBinWidth_C", MatBinBCSRSetBinWidth_SeqBinBCSR) */
#define BINBCSR_COMPOSED(name, fn) \
  BinBCSRComposed { name, reinterpret_cast<BinBCSRComposedFn>(fn) }

/* Composes every function of the list on obj, or, with clear, removes every one of them. */
template <std::size_t N>
static inline PetscErrorCode BinBCSRComposeList(PetscObject obj, const BinBCSRComposed (&list)[N],
                                                PetscBool   clear)
{
  PetscFunctionBegin;
  for (const BinBCSRComposed &f : list)
    PetscCall(PetscObjectComposeFunction(obj, f.name, clear ? nullptr : f.fn));
  PetscFunctionReturn(0);
}

/* The slots of o that seq and mpi fill with the same function of common/ (whole-matrix queries and
   fills, MatPermute, products with other types; and, through the AIJ shadow, submatrices,
   finite-difference colouring and PCGAMG's graph). Each type's table calls it, then names its own. */
static inline void BinBCSRSetCommonOps(struct _MatOps &o)
{
  o.setrandom             = MatSetRandom_BinBCSR;
  o.realpart              = MatRealPart_BinBCSR;
  o.imaginarypart         = MatImaginaryPart_BinBCSR;
  o.issymmetric           = MatIsSymmetric_BinBCSR;
  o.findzerodiagonals     = MatFindZeroDiagonals_BinBCSR;
  o.findnonzerorows       = MatFindNonzeroRows_BinBCSR;
  o.permute               = MatPermute_BinBCSR;
  o.productsetfromoptions = MatProductSetFromOptions_BinBCSR;
  o.increaseoverlap       = MatIncreaseOverlap_BinBCSR;
  o.createsubmatrices     = MatCreateSubMatrices_BinBCSR;
  o.fdcoloringcreate      = MatFDColoringCreate_BinBCSR;
  o.fdcoloringsetup       = MatFDColoringSetUp_BinBCSR;
  o.fdcoloringapply       = MatFDColoringApply_BinBCSR;
  o.creategraph           = MatCreateGraph_BinBCSR;
}

#endif
