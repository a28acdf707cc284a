#include "physics/articulated_scenes.hpp"

#include <cmath>
#include <stdexcept>

namespace physics {

// A box body whose local x axis runs from p to q (the bar between two joint points).
static RigidBody bar_between(const Eigen::Vector3d &p, const Eigen::Vector3d &q, double mass,
                             const Eigen::Vector3d &cross_size, Eigen::Vector3d &size)
{
  RigidBody             b;
  const Eigen::Vector3d d = q - p;
  size                    = Eigen::Vector3d(d.norm(), cross_size.y(), cross_size.z());
  b.mass                  = mass;
  b.inertia_body          = box_inertia(mass, size);
  b.position              = 0.5 * (p + q);
  b.orientation           = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(), d.normalized());
  return b;
}

ArticulatedScene make_chain(const ChainOptions &opt)
{
  if (opt.links < 1) throw std::invalid_argument("a chain needs at least one link");
  // a body and a joint per link, each with its dense 3x3 blocks: 1e8 links ran on filling memory
  if (opt.links > 1000000) throw std::invalid_argument("a chain has at most 1,000,000 links");
  // checked here, where the option is named: a zero-length bar would surface later as a degenerate body
  if (!(opt.link_length > 0) || !std::isfinite(opt.link_length) || !(opt.link_width > 0) ||
      !std::isfinite(opt.link_width))
    throw std::invalid_argument("the chain's link length and width must be positive and finite");
  if (!std::isfinite(opt.angle)) throw std::invalid_argument("the chain's angle must be finite");
  ArticulatedScene      scene;
  const Eigen::Vector3d down(std::sin(opt.angle), -std::cos(opt.angle), 0);
  Eigen::Vector3d       top = Eigen::Vector3d::Zero();
  for (int i = 0; i < opt.links; ++i) {
    const double t = opt.links > 1 ? double(i) / (opt.links - 1) : 0.0;
    // geometric in between, through the logarithms: the ratio itself (1e-300 / 1e300) underflows to 0;
    // the end links and equal masses exactly as given
    const double    mass = opt.mass_first == opt.mass_last || t == 0 ? opt.mass_first
                           : t == 1                                  ? opt.mass_last
                                    : std::exp((1 - t) * std::log(opt.mass_first) + t * std::log(opt.mass_last));
    Eigen::Vector3d size;
    scene.bodies.push_back(bar_between(top, top + opt.link_length * down, mass,
                                       Eigen::Vector3d(0, opt.link_width, opt.link_width), size));
    scene.body_sizes.push_back(size);
    BallJoint j;
    j.body_a   = i - 1; // kWorld for the first link
    j.anchor_a = i == 0 ? top : Eigen::Vector3d(opt.link_length / 2, 0, 0);
    j.body_b   = i;
    j.anchor_b = Eigen::Vector3d(-opt.link_length / 2, 0, 0);
    scene.joints.push_back(j);
    top += opt.link_length * down;
  }
  return scene;
}

ArticulatedScene make_bridge(const BridgeOptions &opt)
{
  if (opt.chains < 1 || opt.links < 2 || opt.tie_every < 1)
    throw std::invalid_argument("a bridge needs chains >= 1, links >= 2, tie_every >= 1");
  if ((double)opt.chains * opt.links > 1000000)
    throw std::invalid_argument("a bridge has at most 1,000,000 planks");
  // the arc's sag (0, negative or NaN gave a singular joint matrix and a failed solve, with no word
  // about the sag); a sag past the arc's half circle is reached at its bound
  if (!(opt.sag > 0) || !std::isfinite(opt.sag))
    throw std::invalid_argument("the bridge's sag must be positive and finite");
  ArticulatedScene scene;
  // Circular arc through the nodes with equal chords plank_length, lowest point `sag` below the anchors.
  const int n          = opt.links;
  double    half_angle = 0.5; // solve sag = R (1 - cos a) with R = l / (2 sin(a / n)) by bisection
  double    lo = 1e-6, hi = 3.0;
  for (int it = 0; it < 200; ++it) {
    half_angle                                           = 0.5 * (lo + hi);
    const double R                                       = opt.plank_length / (2 * std::sin(half_angle / n));
    (R * (1 - std::cos(half_angle)) < opt.sag ? lo : hi) = half_angle;
  }
  const double                 R = opt.plank_length / (2 * std::sin(half_angle / n));
  std::vector<Eigen::Vector3d> nodes(n + 1);
  for (int i = 0; i <= n; ++i) {
    const double phi = -half_angle + 2 * half_angle * i / n;
    nodes[i]         = Eigen::Vector3d(R * std::sin(phi), R * (std::cos(half_angle) - std::cos(phi)), 0);
  }
  const double thickness = 0.05;
  for (int c = 0; c < opt.chains; ++c) {
    const Eigen::Vector3d offset(0, 0, c * opt.plank_width);
    const int             first = static_cast<int>(scene.bodies.size());
    for (int i = 0; i < n; ++i) {
      Eigen::Vector3d size;
      scene.bodies.push_back(bar_between(nodes[i] + offset, nodes[i + 1] + offset, opt.plank_mass,
                                         Eigen::Vector3d(0, thickness, 0.9 * opt.plank_width), size));
      scene.body_sizes.push_back(size);
    }
    const Eigen::Vector3d half(opt.plank_length / 2, 0, 0);
    for (int i = 0; i <= n; ++i) {
      BallJoint j;
      j.body_a   = i == 0 ? kWorld : first + i - 1;
      j.anchor_a = i == 0 ? Eigen::Vector3d(nodes[0] + offset) : half;
      j.body_b   = i == n ? kWorld : first + i;
      j.anchor_b = i == n ? Eigen::Vector3d(nodes[n] + offset) : Eigen::Vector3d(-half);
      scene.joints.push_back(j);
    }
    if (c > 0)
      for (int i = opt.tie_every / 2; i < n; i += opt.tie_every) {
        BallJoint j;
        j.body_a   = first - n + i;
        j.anchor_a = Eigen::Vector3d(0, 0, opt.plank_width / 2);
        j.body_b   = first + i;
        j.anchor_b = Eigen::Vector3d(0, 0, -opt.plank_width / 2);
        scene.joints.push_back(j);
      }
  }
  return scene;
}

ArticulatedScene make_four_bar()
{
  ArticulatedScene      scene;
  const Eigen::Vector3d p[4] = {{0, 0, 0}, {0.4, 1.0, 0}, {2.0, 1.3, 0}, {2.2, 0, 0}};
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d size;
    scene.bodies.push_back(bar_between(p[i], p[i + 1], 1.0, Eigen::Vector3d(0, 0.05, 0.05), size));
    scene.body_sizes.push_back(size);
  }
  for (int i = 0; i < 4; ++i) {
    BallJoint j;
    j.body_a   = i == 0 ? kWorld : i - 1;
    j.anchor_a = i == 0 ? p[0] : Eigen::Vector3d(scene.body_sizes[i - 1].x() / 2, 0, 0);
    j.body_b   = i == 3 ? kWorld : i;
    j.anchor_b = i == 3 ? p[3] : Eigen::Vector3d(-scene.body_sizes[i].x() / 2, 0, 0);
    scene.joints.push_back(j);
  }
  return scene;
}

} // namespace physics
