#include "physics/kinematic_loops.hpp"

#include <numeric>

namespace physics {

std::vector<int> loop_closing_joints(const ArticulatedScene &scene)
{
  const int        nb = static_cast<int>(scene.bodies.size());
  std::vector<int> parent(nb + 1); // node nb is the world
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  std::vector<int> closing;
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    const BallJoint &jt = scene.joints[j];
    const int a = find(jt.body_a == kWorld ? nb : jt.body_a), b = find(jt.body_b == kWorld ? nb : jt.body_b);
    if (a == b) closing.push_back(static_cast<int>(j));
    else parent[a] = b;
  }
  return closing;
}

} // namespace physics
