// Small helpers shared by the benchmark programs.
#pragma once
#include <petscmat.h>
#include <petscbinbcsr.h>
#include <string>
#include <vector>

// Replaces *A (any assembled matrix type) by a MATBINBCSR copy with symmetric storage: all its rows
// are handed over, the type keeps the upper block triangle (the _sym formats of the benchmarks). The
// options database's -mat_binbcsr_* options apply to the copy, except the storage and precision.
PetscErrorCode ReplaceWithBinBCSRSymmetric(Mat *A);

// The same with the storage and the value precision chosen (set before the layout is built, so the
// tuner times the layout in that precision; a precision changed after the build keeps the bin width
// and stream count tuned for the old one).
PetscErrorCode ReplaceWithBinBCSR(Mat *A, PetscBool symmetric, MatBinBCSRPrecision precision);

// "a,b,,c" -> {"a", "b", "c"}: comma lists given as options.
std::vector<std::string> SplitList(const std::string &s);

// SplitList of the value of option (named in the message); a list with no entry (",", "") is an
// error on comm: a benchmark given one printed an empty table and exited 0.
PetscErrorCode SplitOptionList(MPI_Comm comm, const char *option, const std::string &value,
                               std::vector<std::string> *list);

// The message of the last PETSc error, without trailing blanks.
std::string LastErrorText();

// Runs f with errors returned instead of printed and aborted; a format that is not there (yet), or
// refuses the matrix, becomes a row with a note instead of ending the benchmark.
template <class F> PetscErrorCode Try(F f, std::string *note)
{
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr));
  const PetscErrorCode ierr = f();
  PetscCall(PetscPopErrorHandler());
  if (ierr) *note = LastErrorText();
  return 0;
}
