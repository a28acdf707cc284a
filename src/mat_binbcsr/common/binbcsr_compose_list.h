/* The composed functions of a binbcsr type (seq or mpi) from ONE list: MatCreate composes every entry
   of the type's list and MatDestroy clears the same entries, so a name cannot be composed and left
   behind when the matrix changes type (MatConvert in place, MatSetType again). */
#ifndef BINBCSR_COMPOSE_LIST_H
#define BINBCSR_COMPOSE_LIST_H

#include <petscsys.h>
#include <cstddef>

/* PETSc stores every composed function as void (*)(void); its name says the signature. */
typedef void (*BinBCSRComposedFn)(void);

struct BinBCSRComposed {
  const char       *name; /* "MatBinBCSRSetBinWidth_C", ... */
  BinBCSRComposedFn fn;
};

/* One entry of a list: BINBCSR_COMPOSED("MatBinBCSRSetBinWidth_C", MatBinBCSRSetBinWidth_SeqBinBCSR) */
#define BINBCSR_COMPOSED(name, fn) BinBCSRComposed{name, reinterpret_cast<BinBCSRComposedFn>(fn)}

/* Composes every function of the list on obj, or, with clear, removes every one of them. */
template <std::size_t N>
static inline PetscErrorCode BinBCSRComposeList(PetscObject obj, const BinBCSRComposed (&list)[N], PetscBool clear)
{
  PetscFunctionBegin;
  for (const BinBCSRComposed &f : list) PetscCall(PetscObjectComposeFunction(obj, f.name, clear ? nullptr : f.fn));
  PetscFunctionReturn(0);
}

#endif
