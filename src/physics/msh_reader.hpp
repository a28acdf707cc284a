// gmsh .msh reader (ASCII formats 2.2 and 4.1) for tetrahedral meshes with 4 or 10 nodes.
#pragma once
#include "physics/tet_mesh.hpp"

#include <istream>
#include <string>

namespace physics {

// Reads the tetrahedra (gmsh types 4 and 11) and the nodes they use; other elements (points, lines,
// triangles) are skipped, unused nodes dropped and nodes renumbered 0..n-1 in file order. Quadratic
// elements are reordered from gmsh's edge order (01 12 20 30 32 31) to ours (01 12 20 03 13 23).
// Throws std::runtime_error "<name>:<line>: <what>" for: unknown or binary format, missing or
// unterminated sections, counts that do not match the data, malformed numbers, undefined or duplicate
// node tags, a mix of linear and quadratic tetrahedra, no tetrahedra, and inverted or zero-volume
// elements.
TetMesh read_msh(std::istream &in, const std::string &name = "<stream>");
TetMesh read_msh_file(const std::string &path);

} // namespace physics
