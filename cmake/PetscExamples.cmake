# Finds the example sources and data files of the PETSc in use (pkg-config's PETSc), so that the
# stock PETSc programs the tests build come from that version. Debian ships them in
# libpetscX.Y-dev-examples, under PETSc's prefix (share/petsc/examples, share/petsc/datafiles) or
# /usr/share/petsc/X.Y/share/petsc. Sets PETSC_EXAMPLES_DIR (the examples' src/) and
# PETSC_DATAFILES_DIR; stops configuring with one message naming the package when they are absent.
pkg_get_variable(PETSC_PREFIX PETSc prefix)
string(REGEX MATCH "^[0-9]+\\.[0-9]+" PETSC_SERIES "${PETSC_VERSION}")
set(_petsc_share_dirs ${PETSC_PREFIX}/share/petsc /usr/share/petsc/${PETSC_SERIES}/share/petsc)
find_path(PETSC_EXAMPLES_DIR ksp/ksp/tutorials/ex2.c
  PATHS ${_petsc_share_dirs} PATH_SUFFIXES examples/src NO_DEFAULT_PATH)
find_path(PETSC_DATAFILES_DIR matrices/spd-real-int32-float64
  PATHS ${_petsc_share_dirs} PATH_SUFFIXES datafiles NO_DEFAULT_PATH)
if(NOT PETSC_EXAMPLES_DIR OR NOT PETSC_DATAFILES_DIR)
  string(REPLACE ";" " or " _where "${_petsc_share_dirs}")
  message(FATAL_ERROR
    "PETSc ${PETSC_VERSION}'s example sources and data files are missing (looked in ${_where}). "
    "The tests build PETSc's own example programs and load its data matrices: install the package "
    "libpetsc${PETSC_SERIES}-dev-examples (scripts/setup does, as root), then configure again.")
endif()
message(STATUS "PETSc ${PETSC_VERSION} examples: ${PETSC_EXAMPLES_DIR}, data files: ${PETSC_DATAFILES_DIR}")
