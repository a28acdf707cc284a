// Kinematic loops of a joint graph (bodies and the world as nodes, joints as edges): a spanning forest
// and the loop-closing joints outside it. Each loop-closing joint adds one independent loop; only loops
// can make J M^-1 J^T singular (a tree of ball joints always has full row rank).
#pragma once
#include "physics/articulated_scene.hpp"

#include <vector>

namespace physics {

// Joints (indices) that close a loop when the joints are added in order to a union-find forest.
std::vector<int> loop_closing_joints(const ArticulatedScene &scene);

} // namespace physics
