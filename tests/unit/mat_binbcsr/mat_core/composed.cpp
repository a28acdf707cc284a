// The composed functions of a binbcsr matrix go with its type: MatSetType to another type on the same
// matrix (PETSc calls the old type's destroy and keeps the header) leaves none of them behind (a name
// the new type composes itself, such as MatSetValuesCOO_C, then holds the new type's function), and
// the public getters answer as on any other type.
#include "support/mat_support.hpp"

#include <string>
#include <vector>

namespace {

typedef void (*Fn)(void);

Fn composed(Mat A, const char *name)
{
  Fn f = nullptr;
  REQUIRE(PetscObjectQueryFunction((PetscObject)A, name, &f) == 0);
  return f;
}

void check_cleared(MatType type, const std::vector<std::string> &names)
{
  Mat      A;
  PetscInt n = 6;
  REQUIRE(MatCreate(PETSC_COMM_WORLD, &A) == 0);
  REQUIRE(MatSetSizes(A, PETSC_DECIDE, PETSC_DECIDE, n, n) == 0);
  REQUIRE(MatSetType(A, type) == 0);
  REQUIRE(MatSetUp(A) == 0);
  std::vector<Fn> before;
  for (const std::string &name : names) {
    CAPTURE(name);
    before.push_back(composed(A, name.c_str()));
    CHECK(before.back() != nullptr);
  }
  REQUIRE(MatSetType(A, MATAIJ) == 0);
  for (size_t k = 0; k < names.size(); k++) {
    CAPTURE(names[k]);
    CHECK(composed(A, names[k].c_str()) != before[k]); // gone, or the new type's own
  }
  PetscInt bw = -1;
  REQUIRE(MatBinBCSRGetBinWidth(A, &bw) == 0);
  CHECK(bw == 0); // the getter's answer on other types
  REQUIRE(MatDestroy(&A) == 0);
}

} // namespace

TEST_CASE("a binbcsr matrix set to another type keeps none of its composed functions", "[mat_core][composed]")
{
  PetscMPIInt size;
  REQUIRE(MPI_Comm_size(PETSC_COMM_WORLD, &size) == 0);
  std::vector<std::string> names = {"MatBinBCSRSetBinWidth_C",
                                    "MatBinBCSRGetBinWidth_C",
                                    "MatBinBCSRSetPrecision_C",
                                    "MatBinBCSRGetPrecision_C",
                                    "MatBinBCSRSetSymmetricStorage_C",
                                    "MatBinBCSRGetSymmetricStorage_C",
                                    "MatBinBCSRSetCOOMirror_C",
                                    "MatBinBCSRGetCOOMirror_C",
                                    "MatBinBCSRSetStreams_C",
                                    "MatBinBCSRGetStreams_C",
                                    "MatBinBCSRSetPrefetch_C",
                                    "MatBinBCSRGetPrefetch_C",
                                    "MatBinBCSRSetXLoad_C",
                                    "MatBinBCSRGetXLoad_C",
                                    "MatSetPreallocationCOO_C",
                                    "MatSetValuesCOO_C",
                                    "MatMultDotLocal_C",
                                    "MatProductSetFromOptions_anytype_C",
                                    "MatAXPYGetPreallocation_C"};
  if (size == 1) {
    for (const char *s : {"MatSeqAIJSetPreallocation_C", "MatSeqBAIJSetPreallocation_C",
                          "MatConvert_seqbinbcsr_seqaij_C", "MatConvert_seqbinbcsr_seqbaij_C"})
      names.push_back(s);
#if defined(PETSC_HAVE_HYPRE)
    names.push_back("MatConvert_seqbinbcsr_hypre_C");
#endif
  } else {
    for (const char *s : {"MatMPIAIJSetPreallocation_C", "MatMPIBAIJSetPreallocation_C",
                          "MatGetDiagonalBlock_C", "MatConvert_mpibinbcsr_mpiaij_C"})
      names.push_back(s);
#if defined(PETSC_HAVE_HYPRE)
    names.push_back("MatConvert_mpibinbcsr_hypre_C");
#endif
  }
  check_cleared(MATBINBCSR, names);
}
