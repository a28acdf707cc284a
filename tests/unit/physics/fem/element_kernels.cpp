// The batched element kernels (element_kernels.hpp over SIMD lanes, element_batch.cpp) against the
// scalar reference loop, element by element: random, strongly stretched, rigidly rotated, inverted,
// nearly flat, flat and collapsed elements, P1 and P2, with and without blocks, damping, fixed nodes
// and corotation, in every body set this CPU runs (portable, avx2, avx512), each targeted set also
// against the portable one; and the fixed-step polar kernel against the scalar polar decomposition.
#include <catch2/catch.hpp>

#include "physics/corotational_assembly.hpp"
#include "physics/element_batch.hpp"
#include "physics/element_kernels.hpp"
#include "physics/polar_decomposition.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

using namespace physics;

namespace {

Eigen::Matrix3d random_rotation(std::mt19937 &rng)
{
  std::normal_distribution<double> normal(0, 1);
  Eigen::Quaterniond               q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

// Kinds of current shape, drawn per element.
enum Kind {
  Small,
  Large,
  Rigid,
  Inverted,
  NearlyFlat,
  Flat,
  Collapsed,
  kKinds
};

struct Elements {
  TetMesh             mesh; // disjoint elements: element e owns nodes npe e .. npe e + npe - 1
  std::vector<double> x, v;
  std::vector<int>    kind;
};

// n disjoint elements with random rest shapes (positive volume) and current shapes of every kind, or
// of the kinds listed (element e: kinds[e % kinds.size()]).
Elements make_elements(int order, int n, unsigned seed, const std::vector<int> &kinds = {})
{
  std::mt19937                           rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Elements                               s;
  TetMesh                                lin;
  lin.order = 1;
  for (int e = 0; e < n; ++e) {
    Eigen::Vector3d c[4];
    // Near the origin like a mesh's (they may overlap: no node is shared). Far from it, z = R^T x - X
    // would lose the digits of the rounding of R times |x|, in both kernels alike.
    const Eigen::Vector3d base(0.5 * u(rng), 0.5 * u(rng), 0.5 * u(rng));
    for (int a = 0; a < 4; ++a) c[a] = base + Eigen::Vector3d(u(rng), u(rng), u(rng));
    if ((c[1] - c[0]).cross(c[2] - c[0]).dot(c[3] - c[0]) < 0) std::swap(c[1], c[2]);
    if (std::fabs((c[1] - c[0]).cross(c[2] - c[0]).dot(c[3] - c[0])) < 0.05)
      c[3] += Eigen::Vector3d(0.3, 0.4, 0.5) * 2;
    if ((c[1] - c[0]).cross(c[2] - c[0]).dot(c[3] - c[0]) < 0) std::swap(c[1], c[2]);
    for (int a = 0; a < 4; ++a) {
      for (int d = 0; d < 3; ++d) lin.nodes.push_back(c[a][d]);
      lin.elements.push_back(4 * e + a);
    }
  }
  s.mesh        = order == 2 ? promote_to_quadratic(lin) : lin;
  const int npe = s.mesh.nodes_per_element();
  s.x.assign(s.mesh.nodes.size(), 0.0);
  s.v.resize(s.x.size());
  for (double &w : s.v) w = u(rng);
  for (int e = 0; e < n; ++e) {
    const int  kind = kinds.empty() ? e % kKinds : kinds[e % kinds.size()];
    const int *nd   = &s.mesh.elements[static_cast<size_t>(e) * npe];
    s.kind.push_back(kind);
    const Eigen::Matrix3d Q = random_rotation(rng);
    Eigen::Matrix3d       A = Eigen::Matrix3d::Identity();
    if (kind == Small || kind == Inverted || kind == NearlyFlat || kind == Flat)
      for (int j = 0; j < 9; ++j) A.data()[j] += 0.01 * u(rng);
    if (kind == Large)
      for (int j = 0; j < 9; ++j) A.data()[j] += 0.4 * u(rng);
    const Eigen::Vector3d t(u(rng), u(rng), u(rng));
    for (int a = 0; a < npe; ++a) {
      const Eigen::Vector3d X               = Eigen::Vector3d::Map(&s.mesh.nodes[3 * nd[a]]);
      Eigen::Vector3d::Map(&s.x[3 * nd[a]]) = Q * A * X + t;
    }
    // Corner 3 moved onto the plane of the other corners (Flat), just off it (NearlyFlat), through it
    // (Inverted), or all corners onto corner 0 (Collapsed).
    Eigen::Vector3d c[4];
    for (int a = 0; a < 4; ++a) c[a] = Eigen::Vector3d::Map(&s.x[3 * nd[a]]);
    const Eigen::Vector3d normal = (c[1] - c[0]).cross(c[2] - c[0]).normalized();
    const double          h      = (c[3] - c[0]).dot(normal);
    if (kind == Flat) c[3] -= h * normal;
    if (kind == NearlyFlat) c[3] -= (h - 1e-7 * std::fabs(h)) * normal;
    if (kind == Inverted) c[3] -= 1.5 * h * normal;
    if (kind == Collapsed) c[1] = c[2] = c[3] = c[0];
    for (int a = 0; a < 4; ++a) Eigen::Vector3d::Map(&s.x[3 * nd[a]]) = c[a];
    if (order == 2) // edge nodes: midpoints of the moved corners, then bent a little (curved current edges)
      for (int k = 0; k < 6; ++k)
        for (int d = 0; d < 3; ++d)
          s.x[3 * nd[4 + k] + d] =
            0.5 * (c[kTetEdges[k][0]][d] + c[kTetEdges[k][1]][d]) + (kind == Collapsed ? 0 : 0.01 * u(rng));
  }
  return s;
}

double max_abs(const double *p, size_t n)
{
  double m = 0;
  for (size_t k = 0; k < n; ++k) m = std::max(m, std::fabs(p[k]));
  return m;
}

// The worst element-by-element differences of one element loop's output from another's: rotations
// (norm), forces (relative to the element's largest reference force, or for a rigidly moved element,
// whose forces are round-off, to those of a 0.1% strain) and blocks (relative to the element's largest
// reference block entry). Fails at once on a non-finite entry.
struct Differences {
  double R = 0, rhs = 0, block = 0;
  int    compared = 0; // elements whose blocks were compared
};

struct LoopOutput {
  std::vector<double>          values, rhs;
  std::vector<Eigen::Matrix3d> R;
  long long                    scalar_path = 0;
};

Differences element_differences(const FemModel &m, const std::vector<int> &elements, const BlockPattern &p,
                                bool blocks, double young, const LoopOutput &ref, const LoopOutput &out)
{
  Differences d;
  const int   npe = m.npe;
  for (size_t i = 0; i < elements.size(); ++i) {
    const int e      = elements[i];
    d.R              = std::max(d.R, (ref.R[i] - out.R[i]).norm());
    const int *nd    = &m.mesh.elements[static_cast<size_t>(e) * npe];
    double     scale = 1e-3 * young * std::cbrt(m.volume[e] * m.volume[e]), diff = 0;
    for (int a = 0; a < npe; ++a) scale = std::max(scale, max_abs(&ref.rhs[3 * nd[a]], 3));
    for (int a = 0; a < npe; ++a)
      for (int k = 0; k < 3; ++k) {
        REQUIRE(std::isfinite(out.rhs[3 * nd[a] + k]));
        diff = std::max(diff, std::fabs(out.rhs[3 * nd[a] + k] - ref.rhs[3 * nd[a] + k]));
      }
    d.rhs = std::max(d.rhs, diff / std::max(scale, 1e-300));
    if (!blocks) continue;
    scale = diff = 0;
    for (int k = 0; k < npe * npe; ++k) {
      const int slot = p.element_slots[i * npe * npe + k];
      if (slot < 0) continue;
      const size_t at = 9 * static_cast<size_t>(slot & kSlotIndexMask);
      scale           = std::max(scale, max_abs(&ref.values[at], 9));
      for (int j = 0; j < 9; ++j) {
        REQUIRE(std::isfinite(out.values[at + j]));
        diff = std::max(diff, std::fabs(out.values[at + j] - ref.values[at + j]));
      }
    }
    d.block = std::max(d.block, diff / std::max(scale, 1e-300));
    ++d.compared;
  }
  return d;
}

// What fem_energy's u^T K0 u / 2 of element e can be off by in floating point, plus 1e-12 of it: the
// rest-frame displacement u = R^T x - X holds the element's translation, which K0 annihilates only to
// rounding (its rows sum to ~1e-16 |K0|), so a translated element of linear_38k's size carries ~1e-10
// of round-off that the batched form (strains from the gradients, which sum to zero) does not.
double energy_roundoff(const FemModel &m, const double *x, int e, double energy)
{
  const int      *nd = &m.mesh.elements[static_cast<size_t>(e) * m.npe];
  Eigen::Matrix3d Ds, R = Eigen::Matrix3d::Identity();
  for (int k = 0; k < 3; ++k)
    for (int d = 0; d < 3; ++d) Ds(d, k) = x[3 * nd[k + 1] + d] - x[3 * nd[0] + d];
  if (m.settings.corotational) R = rotation_from_deformation(Ds * m.rest_shape_inverse[e]);
  double u2 = 0, k2 = 0;
  for (int a = 0; a < m.npe; ++a)
    u2 +=
      (R.transpose() * Eigen::Vector3d::Map(x + 3 * nd[a]) - Eigen::Vector3d::Map(&m.mesh.nodes[3 * nd[a]]))
        .squaredNorm();
  const int     nb = packed_block_count(m.npe);
  const double *K0 = element_stiffness_blocks(m, e);
  for (int j = 0; j < 9 * nb; ++j) k2 += std::pow(K0[j], 2);
  return 1e-14 * std::sqrt(k2) * u2 + 1e-12 * std::fabs(energy) + 1e-300;
}

// The model of the element tests: a stiff, nearly incompressible material on the elements of s.
FemModel test_model(const Elements &s, bool corotational, bool lumped)
{
  FemSettings settings;
  settings.young        = 3e5;
  settings.poisson      = 0.45;
  settings.corotational = corotational;
  settings.mass         = lumped ? MassLumping::Lumped : MassLumping::Consistent;
  return make_fem_model(s.mesh, settings);
}

// The element list 0..n-1 permuted (37 and n coprime for the n the tests use).
std::vector<int> permuted_elements(int n)
{
  std::vector<int> elements(n);
  for (int e = 0; e < n; ++e) elements[e] = (e * 37) % n;
  return elements;
}

// The body sets this CPU runs (the portable one first, the reference of the others).
std::vector<binbcsr::BodySet> runnable_bodies()
{
  std::vector<binbcsr::BodySet> sets;
  for (binbcsr::BodySet b : {binbcsr::BodySet::Portable, binbcsr::BodySet::AVX2, binbcsr::BodySet::AVX512})
    if (element_body_used(b) == b) sets.push_back(b);
    else WARN("element body " << binbcsr::body_set_name(b) << " not run: this CPU or build lacks it");
  return sets;
}

} // namespace

TEST_CASE("element bodies: the best set this CPU runs, portable on request", "[fem][kernel][batch]")
{
  using binbcsr::BodySet;
  CHECK(element_body_used(BodySet::Portable) == BodySet::Portable);
  const BodySet best = element_body_used(BodySet::Auto);
  CHECK(best != BodySet::Auto);
  CHECK(binbcsr::cpu_runs(best));
#if defined(__x86_64__) && defined(__GNUC__)
  // An x86-64 GCC or Clang build compiles every set, so Auto is the widest set the CPU runs.
  CHECK(best == (binbcsr::cpu_runs(BodySet::AVX512) ? BodySet::AVX512
                 : binbcsr::cpu_runs(BodySet::AVX2) ? BodySet::AVX2
                                                    : BodySet::Portable));
#endif
  // A set the CPU does not run is never chosen; asking for it gives the best one.
  for (BodySet b : {BodySet::AVX2, BodySet::AVX512})
    if (!binbcsr::cpu_runs(b)) CHECK(element_body_used(b) == best);
}

TEST_CASE("batched element kernels equal the scalar ones element by element, in every body set",
          "[fem][kernel][batch]")
{
  const std::vector<binbcsr::BodySet> bodies = runnable_bodies();
  for (int order : {1, 2})
    for (bool corotational : {true, false})
      for (int variant = 0; variant < 4; ++variant) {
        // 0: step with damping (a_M != 0), 1: step without, 2: static Newton step, 3: forces only
        INFO("order " << order << " corotational " << corotational << " variant " << variant);
        const int         n        = 203; // not a multiple of the lane count
        const Elements    s        = make_elements(order, n, 17 + order);
        const FemModel    m        = test_model(s, corotational, variant == 1);
        std::vector<int>  elements = permuted_elements(n);
        std::vector<char> fixed(m.node_count(), 0);
        fixed[3] = fixed[m.node_count() - 1] = 1; // some slots dropped
        const BlockPattern p =
          make_block_pattern(m, elements, fixed, 0, m.node_count(), false); // one COO block per element block
        const StepCoefficients c      = variant == 0   ? implicit_euler_coefficients(0.01, 0.5, 0.002)
                                        : variant == 1 ? implicit_euler_coefficients(0.01)
                                                       : StepCoefficients{1, 0, 0, 0, 1};
        const bool             blocks = variant != 3;
        auto                   run    = [&](ElementKernel kernel, binbcsr::BodySet body) {
          LoopOutput o;
          o.rhs.assign(s.x.size(), 0.0);
          o.R.resize(n);
          reset_block_values(p, o.values);
          o.scalar_path =
            assemble_elements(m, elements, s.x.data(), s.v.data(), c, blocks ? &p : nullptr,
                              blocks ? o.values.data() : nullptr, o.rhs.data(), o.R.data(), kernel, body);
          return o;
        };
        const LoopOutput scalar   = run(ElementKernel::Scalar, binbcsr::BodySet::Auto);
        LoopOutput       portable = {};
        for (binbcsr::BodySet body : bodies) {
          INFO("element body " << binbcsr::body_set_name(body));
          const LoopOutput batched = run(ElementKernel::Batched, body);
          // Every inverted, flat or collapsed element takes the scalar SVD path, regular ones do not.
          if (corotational) {
            long long expected_min = 0, expected_max = 0;
            for (int e = 0; e < n; ++e) {
              const int k = s.kind[e];
              expected_min += (k == Inverted || k == Flat || k == Collapsed);
              expected_max += (k == Inverted || k == Flat || k == Collapsed || k == NearlyFlat || k == Large);
            }
            CHECK(batched.scalar_path >= expected_min);
            CHECK(batched.scalar_path <= expected_max);
          } else {
            CHECK(batched.scalar_path == 0);
          }
          const Differences d =
            element_differences(m, elements, p, blocks, m.settings.young, scalar, batched);
          CHECK(d.R < 1e-12);
          // The scalar reference stops its Newton iteration within ~1e-14 of the rotation; a nearly rigid
          // element's forces (a difference of two large terms) amplify that to ~1e-11 of the floor.
          CHECK(d.rhs < 1e-10);
          CHECK(d.block < 1e-12);
          CHECK((!blocks || d.compared == n));
          // The identity blocks of the fixed nodes are left alone, and nothing else changes.
          if (blocks)
            for (int slot : p.identity_slots) CHECK(batched.values[9 * slot] == 1.0);
          if (body == binbcsr::BodySet::Portable) {
            portable = batched;
            continue;
          }
          // A targeted body against the portable one: the same formulas, so only rounding differs
          // (FMA contraction, another order of the sums); both run the same fixed Newton steps and
          // send the same elements to the scalar path. Measured (GCC 12, Zen 4): R 4.9e-15, blocks
          // 3.5e-15, forces 1.7e-11 of the floor (R's rounding times |x| over a 0.1% strain's
          // forces, as against the scalar loop).
          CHECK(batched.scalar_path == portable.scalar_path);
          const Differences t =
            element_differences(m, elements, p, blocks, m.settings.young, portable, batched);
          CHECK(t.R < 1e-13);
          CHECK(t.rhs < 1e-10);
          CHECK(t.block < 1e-13);
        }
      }
}

TEST_CASE("batches of slightly strained elements, which stop the Newton steps early, equal the scalar "
          "kernels",
          "[fem][kernel][batch]")
{
  // Every lane of most batches passes after kPolarEarlySteps (the other test's batches all hold a
  // Large element and run every step).
  const std::vector<binbcsr::BodySet> bodies = runnable_bodies();
  for (int order : {1, 2}) {
    INFO("order " << order);
    const int              n        = 203;
    const Elements         s        = make_elements(order, n, 41 + order, {Small, Rigid, Small});
    const FemModel         m        = test_model(s, true, false);
    std::vector<int>       elements = permuted_elements(n);
    std::vector<char>      fixed(m.node_count(), 0);
    const BlockPattern     p   = make_block_pattern(m, elements, fixed, 0, m.node_count(), false);
    const StepCoefficients c   = implicit_euler_coefficients(0.01, 0.5, 0.002);
    auto                   run = [&](ElementKernel kernel, binbcsr::BodySet body) {
      LoopOutput o;
      o.rhs.assign(s.x.size(), 0.0);
      o.R.resize(n);
      reset_block_values(p, o.values);
      o.scalar_path = assemble_elements(m, elements, s.x.data(), s.v.data(), c, &p, o.values.data(),
                                                          o.rhs.data(), o.R.data(), kernel, body);
      return o;
    };
    const LoopOutput scalar = run(ElementKernel::Scalar, binbcsr::BodySet::Auto);
    for (binbcsr::BodySet body : bodies) {
      INFO("element body " << binbcsr::body_set_name(body));
      const LoopOutput  batched = run(ElementKernel::Batched, body);
      const Differences d = element_differences(m, elements, p, true, m.settings.young, scalar, batched);
      CHECK(batched.scalar_path == 0);
      CHECK(d.R < 1e-12);
      CHECK(d.rhs < 1e-10);
      CHECK(d.block < 1e-12);
      CHECK(d.compared == n);
    }
  }
}

TEST_CASE("polar kernel in pieces: strains of ~1% pass after kPolarEarlySteps, at the full iteration's R",
          "[fem][polar][batch]")
{
  std::mt19937                     rng(5);
  std::normal_distribution<double> normal(0, 1);
  int                              early = 0;
  double                           worst = 0;
  for (int k = 0; k < 2000; ++k) {
    Eigen::Vector3d sv;
    for (int d = 0; d < 3; ++d) sv[d] = 1.0 + 0.003 * normal(rng);
    const Eigen::Matrix3d F = random_rotation(rng) * sv.asDiagonal() * random_rotation(rng);
    double                X[9], C[9], det, ok, change, R[9], Rfull[9];
    kernels::polar_start<1, 1>(F.data(), X, C, &det, &ok);
    kernels::polar_steps<1, 0, kernels::kPolarEarlySteps>(X, C, &det, &ok, &change);
    const double accepted = kernels::polar_accepted(det, ok, change);
    early += accepted != 0;
    kernels::polar_finish<1, 1>(X, accepted, R);
    REQUIRE(kernels::polar_rotation<1>(F.data(), Rfull) != 0);
    if (accepted != 0)
      worst = std::max(worst, (Eigen::Matrix3d::Map(R) - Eigen::Matrix3d::Map(Rfull)).norm());
    else CHECK((Eigen::Matrix3d::Map(R) - Eigen::Matrix3d::Identity()).norm() == 0);
  }
  CHECK(early > 1900);
  CHECK(worst < 1e-14);
  // Starts near a rotation (det of the normalised start > kPolarNearDet): the unscaled steps the batch
  // takes there pass at the same R; strains of 0.3% always start near and pass.
  int near = 0, near_early = 0;
  worst = 0;
  for (int k = 0; k < 4000; ++k) {
    Eigen::Vector3d sv;
    const double    spread = k % 2 ? 0.003 : 0.03;
    for (int d = 0; d < 3; ++d) sv[d] = 1.0 + spread * normal(rng);
    const Eigen::Matrix3d F = random_rotation(rng) * sv.asDiagonal() * random_rotation(rng);
    double                X[9], C[9], det, ok, change, R[9], Rfull[9];
    kernels::polar_start<1, 1>(F.data(), X, C, &det, &ok);
    REQUIRE(ok != 0);
    if (k % 2) REQUIRE(det > kernels::kPolarNearDet);
    if (det <= kernels::kPolarNearDet) continue;
    ++near;
    kernels::polar_steps<1, 0, kernels::kPolarEarlySteps, 0>(X, C, &det, &ok, &change);
    const double accepted = kernels::polar_accepted(det, ok, change);
    if (k % 2) REQUIRE(accepted != 0);
    if (accepted == 0) continue;
    ++near_early;
    kernels::polar_finish<1, 1>(X, accepted, R);
    REQUIRE(kernels::polar_rotation<1>(F.data(), Rfull) != 0);
    worst = std::max(worst, (Eigen::Matrix3d::Map(R) - Eigen::Matrix3d::Map(Rfull)).norm());
  }
  INFO("near starts " << near << ", passed unscaled " << near_early);
  CHECK(near_early > 2000);
  CHECK(worst < 1e-14);
}

TEST_CASE("fixed-step polar kernel: the scalar rotation where it accepts, the fallback flag elsewhere",
          "[fem][polar][batch]")
{
  std::mt19937                           rng(23);
  std::normal_distribution<double>       normal(0, 1);
  std::uniform_real_distribution<double> uniform(0, 1);
  double                                 worst    = 0;
  int                                    accepted = 0;
  for (int k = 0; k < 4000; ++k) {
    // Singular values 1 +- 1% or with ratios up to 4:1 (3:1 stretch), overall scale 1e-3..1e3.
    Eigen::Vector3d sv;
    for (int d = 0; d < 3; ++d) sv[d] = k % 2 ? std::pow(4.0, -0.5 + uniform(rng)) : 1.0 + 0.01 * normal(rng);
    const Eigen::Matrix3d F =
      std::pow(10.0, -3 + 6 * uniform(rng)) * random_rotation(rng) * sv.asDiagonal() * random_rotation(rng);
    double       R[9];
    const double ok = kernels::polar_rotation<1>(F.data(), R);
    accepted += ok != 0;
    REQUIRE(ok != 0);
    worst = std::max(worst, (Eigen::Matrix3d::Map(R) - rotation_from_deformation(F)).norm());
  }
  CHECK(accepted == 4000);
  CHECK(worst < 1e-12);
  // Refused (identity returned, no NaN): inverted, flat, collapsed, zero, NaN, Inf.
  const Eigen::Matrix3d Q   = random_rotation(rng);
  Eigen::Matrix3d       nan = Eigen::Matrix3d::Identity(), inf = Eigen::Matrix3d::Identity();
  nan(1, 2) = std::nan("");
  inf(0, 1) = std::numeric_limits<double>::infinity();
  for (const Eigen::Matrix3d &F :
       {Eigen::Matrix3d(-Q), Eigen::Matrix3d(Q * Eigen::DiagonalMatrix<double, 3>(1.0, 1.0, -0.2)),
        Eigen::Matrix3d(Q * Eigen::DiagonalMatrix<double, 3>(1.0, 2.0, 0.0)),
        Eigen::Matrix3d(Q * Eigen::DiagonalMatrix<double, 3>(1.0, 0.0, 0.0)),
        Eigen::Matrix3d(Eigen::Matrix3d::Zero()), nan, inf}) {
    double R[9];
    CHECK(kernels::polar_rotation<1>(F.data(), R) == 0);
    CHECK((Eigen::Matrix3d::Map(R) - Eigen::Matrix3d::Identity()).norm() == 0);
  }
}

TEST_CASE("the element pass's energy equals fem_energy's element by element, in every body set",
          "[fem][kernel][batch][energy]")
{
  const std::vector<binbcsr::BodySet> bodies = runnable_bodies();
  for (int order : {1, 2})
    for (bool corotational : {true, false})
      for (bool lumped : {false, true}) {
        INFO("order " << order << " corotational " << corotational << " lumped " << lumped);
        const int              n        = 203; // not a multiple of the lane count
        const Elements         s        = make_elements(order, n, 29 + order);
        const FemModel         m        = test_model(s, corotational, lumped);
        std::vector<int>       elements = permuted_elements(n);
        std::vector<char>      fixed(m.node_count(), 0);
        const BlockPattern     p   = make_block_pattern(m, elements, fixed, 0, m.node_count(), true);
        const StepCoefficients c   = implicit_euler_coefficients(0.01, 0.5, 0.002);
        auto                   run = [&](ElementKernel kernel, binbcsr::BodySet body, bool blocks) {
          std::vector<double> values, rhs(s.x.size(), 0.0), per(3 * static_cast<size_t>(n), -1.0);
          reset_block_values(p, values);
          ElementEnergy E;
          E.per_element = per.data();
          assemble_elements(m, elements, s.x.data(), s.v.data(), c, blocks ? &p : nullptr,
                            blocks ? values.data() : nullptr, rhs.data(), nullptr, kernel, body, &E);
          return std::make_pair(E, per);
        };
        // The definition, element by element, and the scalar loop's figures, which are its sums.
        std::vector<FemEnergy> ref(n);
        std::vector<double>    roundoff(n);
        double                 elastic = 0, kinetic = 0, inverted = 0, roundoff_sum = 0;
        for (int i = 0; i < n; ++i) {
          ref[i]      = element_energy(m, s.x.data(), s.v.data(), elements[i]);
          roundoff[i] = energy_roundoff(m, s.x.data(), elements[i], ref[i].elastic);
          roundoff_sum += roundoff[i];
          elastic += ref[i].elastic;
          kinetic += ref[i].kinetic;
          inverted += element_signed_volume(m.mesh, s.x.data(), elements[i]) > 0 ? 0 : 1;
        }
        CHECK(inverted >= n / kKinds); // the inverted elements at least (flat ones go either way)
        const auto scalar = run(ElementKernel::Scalar, binbcsr::BodySet::Auto, true);
        CHECK(scalar.first.elastic == Approx(elastic).epsilon(1e-14));
        CHECK(scalar.first.kinetic == Approx(kinetic).epsilon(1e-14));
        CHECK(scalar.first.inverted == inverted);
        for (binbcsr::BodySet body : bodies)
          for (bool blocks : {true, false}) {
            INFO("element body " << binbcsr::body_set_name(body) << " blocks " << blocks);
            const auto batched = run(ElementKernel::Batched, body, blocks);
            // Per element: the energy within the definition's round-off, the kinetic energy to rounding.
            double worst_elastic = 0, worst_kinetic = 0, sum_elastic = 0, sum_kinetic = 0, sum_inverted = 0;
            int    flag_differs = 0;
            for (int i = 0; i < n; ++i) {
              const int     e   = elements[i];
              const double *out = &batched.second[3 * static_cast<size_t>(i)];
              REQUIRE(std::isfinite(out[0]));
              REQUIRE(std::isfinite(out[1]));
              worst_elastic    = std::max(worst_elastic, std::fabs(out[0] - ref[i].elastic) / roundoff[i]);
              worst_kinetic    = std::max(worst_kinetic, std::fabs(out[1] - ref[i].kinetic) /
                                                           std::max(std::fabs(ref[i].kinetic), 1e-300));
              const double inv = element_signed_volume(m.mesh, s.x.data(), e) > 0 ? 0 : 1;
              // Without FMA the test is element_signed_volume's to the bit; with it only a flat
              // element's (volume within rounding of zero) may fall on the other side.
              if (body == binbcsr::BodySet::Portable || s.kind[e] != Flat) CHECK(out[2] == inv);
              flag_differs += out[2] != inv;
              sum_elastic += out[0];
              sum_kinetic += out[1];
              sum_inverted += out[2];
            }
            CHECK(worst_elastic < 1);
            CHECK(worst_kinetic < 1e-13);
            CHECK(flag_differs <= n / kKinds + 1);
            // The sums are the per-element figures' (in element order, lane after lane).
            CHECK(batched.first.elastic == Approx(sum_elastic).epsilon(1e-14));
            CHECK(batched.first.kinetic == Approx(sum_kinetic).epsilon(1e-14));
            CHECK(batched.first.inverted == sum_inverted);
            CHECK(std::fabs(batched.first.elastic - elastic) <= roundoff_sum);
            CHECK(batched.first.kinetic == Approx(kinetic).epsilon(1e-13));
          }
      }
}
