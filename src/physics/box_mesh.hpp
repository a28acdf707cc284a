// Procedural beam/box meshes: an nx x ny x nz grid of hexahedra over [0,lx] x [0,ly] x [0,lz], each
// cut into 6 tetrahedra around its main diagonal (Kuhn subdivision, conforming across faces).
#pragma once
#include "physics/tet_mesh.hpp"

namespace physics {

// Linear (order 1) mesh; promote_to_quadratic() makes it quadratic. Throws std::invalid_argument
// for non-positive sizes or counts.
TetMesh make_box_mesh(double lx, double ly, double lz, int nx, int ny, int nz);

} // namespace physics
