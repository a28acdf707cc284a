#include "sim/bench_util.h"

#include <petscbinbcsr.h>

PetscErrorCode ReplaceWithBinBCSRSymmetric(Mat *A)
{
  return ReplaceWithBinBCSR(A, PETSC_TRUE, MAT_BINBCSR_PRECISION_DOUBLE);
}

PetscErrorCode ReplaceWithBinBCSR(Mat *A, PetscBool symmetric, MatBinBCSRPrecision precision)
{
  Mat       S;
  PetscInt  bs, rlo, rhi, m, n;
  PetscBool sym;

  PetscFunctionBegin;
  PetscCall(MatGetLocalSize(*A, &m, &n));
  PetscCall(MatGetBlockSize(*A, &bs));
  PetscCall(MatCreate(PetscObjectComm((PetscObject)*A), &S));
  PetscCall(MatSetSizes(S, m, n, PETSC_DETERMINE, PETSC_DETERMINE));
  PetscCall(MatSetBlockSize(S, bs));
  PetscCall(MatSetType(S, MATBINBCSR));
  /* the -mat_binbcsr_* options (bin width, streams, kernel, tuning, ...) as for the benchmarks' other
     binbcsr matrices; the storage and precision this copy is for are set after them and win */
  PetscCall(MatSetFromOptions(S));
  PetscCall(MatBinBCSRSetSymmetricStorage(S, symmetric));
  PetscCall(
    MatBinBCSRSetPrecision(S, precision)); /* before the layout build: the tuner times this precision */
  PetscCall(MatSetUp(S));
  PetscCall(MatGetOwnershipRange(*A, &rlo, &rhi));
  for (PetscInt r = rlo; r < rhi; r++) {
    PetscInt           nz;
    const PetscInt    *cols;
    const PetscScalar *vals;
    PetscCall(MatGetRow(*A, r, &nz, &cols, &vals));
    PetscCall(MatSetValues(S, 1, &r, nz, cols, vals, INSERT_VALUES));
    PetscCall(MatRestoreRow(*A, r, &nz, &cols, &vals));
  }
  PetscCall(MatAssemblyBegin(S, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(S, MAT_FINAL_ASSEMBLY));
  PetscCall(MatBinBCSRGetSymmetricStorage(S, &sym));
  PetscCheck(sym == symmetric, PetscObjectComm((PetscObject)S), PETSC_ERR_SUP,
             "symmetric storage not available");
  PetscCall(MatDestroy(A));
  *A = S;
  PetscFunctionReturn(0);
}

std::vector<std::string> SplitList(const std::string &s)
{
  std::vector<std::string> out;
  size_t                   start = 0;
  while (start <= s.size()) {
    size_t end = s.find(',', start);
    if (end == std::string::npos) end = s.size();
    if (end > start) out.push_back(s.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

PetscErrorCode SplitOptionList(MPI_Comm comm, const char *option, const std::string &value,
                               std::vector<std::string> *list)
{
  PetscFunctionBegin;
  *list = SplitList(value);
  PetscCheck(!list->empty(), comm, PETSC_ERR_ARG_WRONG, "%s \"%s\" is an empty list: give at least one entry",
             option, value.c_str());
  PetscFunctionReturn(0);
}

std::string LastErrorText()
{
  const char *text     = nullptr;
  char       *specific = nullptr;
  PetscErrorMessage(PETSC_ERR_SUP, &text, &specific);
  std::string s = specific ? specific : (text ? text : "error");
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}
