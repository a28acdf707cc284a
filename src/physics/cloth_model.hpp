// A cloth patch: an n x n particle grid with stretch (grid edges), shear (cell diagonals) and bend
// (two-apart) springs, lumped particle masses, pinned particles and an optional sphere to drape over.
#pragma once
#include <Eigen/Dense>
#include <string>
#include <vector>

namespace physics {

enum class SpringKind : int {
  Stretch = 0,
  Shear   = 1,
  Bend    = 2
};

struct Spring {
  int        a = 0, b = 0;
  double     rest_length = 0;
  double     stiffness   = 0; // N/m
  SpringKind kind        = SpringKind::Stretch;
};

struct SphereCollider {
  bool            enabled = false;
  Eigen::Vector3d centre  = Eigen::Vector3d(0, -0.5, 0);
  double          radius  = 0.3;
};

struct Cloth {
  int                          n = 0; // particles per side; particle (i, j) is i * n + j
  std::vector<Eigen::Vector3d> position, velocity;
  std::vector<double>          mass;
  std::vector<char>            fixed;
  std::vector<Spring>          springs;
  Eigen::Vector3d              gravity = Eigen::Vector3d(0, -9.81, 0);
  double                       damping = 0; // N s/m along each spring
  SphereCollider               sphere;
  int                          particle_count() const { return static_cast<int>(position.size()); }
};

enum class ClothPins {
  TwoCorners,
  FourCorners,
  TopRow,
  None
};

struct ClothOptions {
  int       n          = 160;
  double    size       = 1.0;  // side length, m
  double    total_mass = 0.5;  // kg
  double    k_stretch  = 1000; // N/m per spring
  double    k_shear    = 100;
  double    k_bend     = 10;
  double    damping    = 0.0;
  bool      hanging    = false; // vertical (xy-plane, row 0 at the top) instead of horizontal (xz-plane)
  ClothPins pins       = ClothPins::TwoCorners; // corners of row 0
};

// Throws std::invalid_argument on unusable options (n < 2, non-positive size/mass, negative stiffness).
Cloth make_cloth(const ClothOptions &opt);

// Empty when usable, otherwise the first problem (sizes, masses, spring indices, rest lengths, NaN).
std::string validate_cloth(const Cloth &cloth);

// Kinetic + gravitational + spring energy.
double cloth_energy(const Cloth &cloth);

// Largest length / rest length over the stretch springs (1 = unstretched).
double max_stretch_ratio(const Cloth &cloth);
// The same over the listed springs (indices into cloth.springs), e.g. the stretch springs one process assembles.
double max_stretch_ratio(const Cloth &cloth, const std::vector<int> &springs);

} // namespace physics
