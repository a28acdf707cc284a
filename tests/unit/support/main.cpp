// Catch2 main for the unit tests: PETSc is initialised once for the whole program, and the plug-in's
// types are registered the way a linked user program registers them.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>
#include <petscbinbcsr.h>

int main(int argc, char **argv)
{
  // PETSc sees no arguments: the command line belongs to Catch (test names, -s, ...).
  int    petsc_argc = 1;
  char **petsc_argv = argv;
  if (PetscInitialize(&petsc_argc, &petsc_argv, nullptr, nullptr)) return 1;
  if (PetscBinBCSRRegisterAll()) return 1;
  // Errors that tests provoke on purpose must come back as codes, not print and abort.
  PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
  const int failed = Catch::Session().run(argc, argv);
  PetscPopErrorHandler();
  if (PetscFinalize()) return 1;
  return failed;
}
