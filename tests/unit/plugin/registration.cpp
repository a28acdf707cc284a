#include <catch2/catch.hpp>
#include <petscbinbcsr.h>
#include <dlfcn.h>

TEST_CASE("registration is idempotent and the loader entry point is exported", "[plugin]")
{
  REQUIRE(PetscBinBCSRRegisterAll() == 0);
  REQUIRE(PetscDLLibraryRegister_petscbinbcsr() == 0);
  // The -dll_append loader looks the entry point up by name with dlsym: it must be a C symbol.
  void *self = dlopen(nullptr, RTLD_LAZY);
  REQUIRE(self != nullptr);
  CHECK(dlsym(self, "PetscDLLibraryRegister_petscbinbcsr") != nullptr);
  dlclose(self);
}

TEST_CASE("the setters are no-ops on other matrix types", "[plugin]")
{
  Mat A;
  REQUIRE(MatCreateSeqAIJ(PETSC_COMM_SELF, 4, 4, 1, nullptr, &A) == 0);
  PetscInt bw = -1;
  CHECK(MatBinBCSRSetBinWidth(A, 8) == 0);
  CHECK(MatBinBCSRGetBinWidth(A, &bw) == 0);
  CHECK(bw == 0);
  REQUIRE(MatDestroy(&A) == 0);
}
