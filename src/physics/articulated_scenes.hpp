// Scene generators for the articulated driver and its tests. Gravity is -y; lengths in metres.
#pragma once
#include "physics/articulated_scene.hpp"

namespace physics {

// A chain of `links` slender boxes hanging from the world point (0,0,0), straight, rotated by
// `angle` (radians) about z. Link masses go geometrically from mass_first (top) to mass_last (bottom).
struct ChainOptions {
  int    links       = 10;
  double link_length = 0.5;
  double link_width  = 0.05;
  double mass_first  = 1.0;
  double mass_last   = 1.0;
  double angle       = 0.5;
};
ArticulatedScene make_chain(const ChainOptions &opt);

// A plank bridge: `chains` parallel chains of `links` planks each, hanging in a circular arc between two
// world anchors (`sag` metres deep), neighbouring chains tied together by a ball joint at the side of
// every `tie_every`-th plank. Each anchored chain and each tie closes a kinematic loop.
struct BridgeOptions {
  int    chains       = 136;
  int    links        = 100;
  int    tie_every    = 100;
  double plank_length = 0.5;
  double plank_width  = 0.3;
  double plank_mass   = 10.0;
  double sag          = 10.0;
};
ArticulatedScene make_bridge(const BridgeOptions &opt);

// A four-bar linkage: three bars between ground pivots (0,0,0) and (2.2,0,0), four ball joints, one loop
// through the world.
ArticulatedScene make_four_bar();

} // namespace physics
