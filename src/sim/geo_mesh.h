// Meshing a gmsh geometry (.geo) for the drivers, with a cache of the meshes made.
#pragma once
#include <petscsys.h>

#include <string>

// Meshes `geo` with gmsh (-3, msh 4.1, -clmax `size` when size > 0) on comm's rank 0 into a cache next
// to the program (build/meshes, named by a digest of the file's text and the meshing options), and
// returns the mesh file's path on every rank. max_tets > 0: a size whose mesh is estimated (from the
// body's volume) to have more tetrahedra is refused before gmsh runs; the estimate is made only when
// the mesh is not in the cache yet. geo by value: a caller may name the same string as geo and msh.
PetscErrorCode GeoMesh(MPI_Comm comm, std::string geo, double size, double max_tets, std::string *msh);
