/* A C++ object composed on a PETSc object (in a PetscContainer), so that it lives as long as the
   object: the routing of a factor, the AIJ shadow of a matrix, a submatrix's value map, a product's
   context. Destroy frees it when the object goes (or another is composed under the same key). */
#ifndef BINBCSR_COMPOSED_H
#define BINBCSR_COMPOSED_H

#include <petscsys.h>

namespace binbcsr {

template <class T> PetscErrorCode DeleteComposed(void *p)
{
  delete static_cast<T *>(p);
  return 0;
}

/* *ptr: the object composed on obj under key, or NULL */
template <class T> PetscErrorCode QueryComposed(PetscObject obj, const char *key, T **ptr)
{
  PetscContainer c;

  PetscFunctionBegin;
  *ptr = nullptr;
  PetscCall(PetscObjectQuery(obj, key, (PetscObject *)&c));
  if (c) PetscCall(PetscContainerGetPointer(c, (void **)ptr));
  PetscFunctionReturn(0);
}

/* composes ptr (owned from now on by obj) under key */
template <class T>
PetscErrorCode Compose(PetscObject obj, const char *key, T *ptr,
                       PetscErrorCode (*destroy)(void *) = DeleteComposed<T>)
{
  PetscContainer c;

  PetscFunctionBegin;
  PetscCall(PetscContainerCreate(PETSC_COMM_SELF, &c));
  PetscCall(PetscContainerSetPointer(c, ptr));
  PetscCall(PetscContainerSetUserDestroy(c, destroy));
  PetscCall(PetscObjectCompose(obj, key, (PetscObject)c));
  PetscCall(PetscContainerDestroy(&c));
  PetscFunctionReturn(0);
}

/* the object under key, a new T composed there first if there is none */
template <class T>
PetscErrorCode GetOrCompose(PetscObject obj, const char *key, T **ptr,
                            PetscErrorCode (*destroy)(void *) = DeleteComposed<T>)
{
  PetscFunctionBegin;
  PetscCall(QueryComposed(obj, key, ptr));
  if (!*ptr) {
    *ptr = new T;
    PetscCall(Compose(obj, key, *ptr, destroy));
  }
  PetscFunctionReturn(0);
}

} // namespace binbcsr

#endif
