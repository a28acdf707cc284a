#include "physics/cloth_step.hpp"

#include "physics/cloth_springs.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace physics {

ClothSystem make_cloth_system(const Cloth &cloth)
{
  return make_cloth_system(cloth, std::vector<char>(cloth.particle_count(), 1),
                           [](int, int) { return true; });
}

ClothSystem make_cloth_system(const Cloth &cloth, const std::vector<char> &own,
                              const std::function<bool(int row, int col)> &keep)
{
  if ((int)own.size() != cloth.particle_count())
    throw std::invalid_argument("make_cloth_system: one ownership flag per particle needed");
  ClothSystem s;
  s.n_particles = cloth.particle_count();
  s.diagonal_block.assign(s.n_particles, -1);
  for (int p = 0; p < s.n_particles; ++p)
    if (own[p]) {
      s.diagonal_block[p] = (int)s.block_row.size();
      s.block_row.push_back(p), s.block_col.push_back(p);
    }
  auto list = [&](int row, int col) {
    if (!own[row] || !keep(row, col)) return -1;
    s.block_row.push_back(row), s.block_col.push_back(col);
    return (int)s.block_row.size() - 1;
  };
  for (size_t k = 0; k < cloth.springs.size(); ++k) {
    const Spring &sp = cloth.springs[k];
    if (!own[sp.a] && !own[sp.b]) continue;
    s.springs.push_back((int)k);
    if (sp.kind == SpringKind::Stretch) s.stretch_springs.push_back((int)k);
    s.block_ab.push_back(list(sp.a, sp.b));
    s.block_ba.push_back(list(sp.b, sp.a));
  }
  s.block_values.assign(9 * s.block_row.size(), 0.0);
  s.rhs.assign(3 * s.n_particles, 0.0);
  s.dv.assign(3 * s.n_particles, 0.0);
  s.strain_limiter = make_strain_limiter(cloth);
  return s;
}

std::string validate_params(const ClothParams &p)
{
  if (!(p.dt > 0) || !std::isfinite(p.dt)) return "time step must be positive and finite";
  return validate_strain_limit(p.strain_limit);
}

namespace {

// One spring's share of the system: its block alpha I + beta d d^T on both diagonal blocks and (negated)
// on its off-diagonal blocks that are listed (ab, ba: COO block indices or -1), and h f - h^2 K dv to the
// right-hand side of its assembled ends.
inline void add_spring(const Cloth &cloth, ClothSystem &sys, const Spring &sp, const SpringTerms &t, double h,
                       int block_ab, int block_ba)
{
  const double h2 = h * h;
  // The spring's block of M + h D + h^2 K: alpha I + beta d d^T (symmetric).
  const double           alpha = h2 * t.k_iso, beta = h2 * t.k_dir + h * t.damping;
  const Eigen::Vector3d &d = t.direction;
  double                 block[9]; // computed once per pair and mirrored: exactly symmetric, so a
  for (int r = 0; r < 3; ++r)      // type that keeps one triangle sees the same matrix as one keeping both
    for (int c = r; c < 3; ++c)
      block[3 * r + c] = block[3 * c + r] = beta * d[r] * d[c] + (r == c ? alpha : 0.0);
  // The spring's K acts on dv_a - dv_b; a pinned end has dv = 0, so its row, column and rhs stay out.
  // An end whose row is assembled elsewhere (diagonal_block < 0) is skipped the same way here.
  const bool   fa = cloth.fixed[sp.a], fb = cloth.fixed[sp.b];
  const int    ia = fa ? -1 : sys.diagonal_block[sp.a], ib = fb ? -1 : sys.diagonal_block[sp.b];
  const double coupling = !fa && !fb ? -1.0 : 0.0;
  // One loop per destination (the four never overlap): each becomes a 9-wide vector add or store. Tested
  // inside one loop per entry, as before, they ran entry by entry and took half the assembly.
  double *values = sys.block_values.data();
  if (ia >= 0)
    for (int k = 0; k < 9; ++k) values[9 * ia + k] += block[k];
  if (ib >= 0)
    for (int k = 0; k < 9; ++k) values[9 * ib + k] += block[k];
  if (block_ab >= 0)
    for (int k = 0; k < 9; ++k) values[9 * block_ab + k] = coupling * block[k];
  if (block_ba >= 0)
    for (int k = 0; k < 9; ++k) values[9 * block_ba + k] = coupling * block[k];
  // h f_a - h^2 K (v_a - v_b), K = k_iso I + k_dir d d^T
  const Eigen::Vector3d dvel    = cloth.velocity[sp.a] - cloth.velocity[sp.b];
  const Eigen::Vector3d fa_term = h * t.force_on_a - h2 * (t.k_iso * dvel + t.k_dir * d.dot(dvel) * d);
  double               *rhs     = sys.rhs.data();
  if (ia >= 0)
    for (int k = 0; k < 3; ++k) rhs[3 * sp.a + k] += fa_term[k];
  if (ib >= 0)
    for (int k = 0; k < 3; ++k) rhs[3 * sp.b + k] -= fa_term[k];
}

} // namespace

void assemble_cloth_system(const Cloth &cloth, const ClothParams &params, ClothSystem &sys)
{
  const double h = params.dt;
  // rhs = h (f - h K v), built as h m g first, then spring by spring. Diagonal blocks start at M and
  // accumulate; every off-diagonal block belongs to one spring and is written once (no clearing pass).
  for (int p = 0; p < sys.n_particles; ++p) {
    if (sys.diagonal_block[p] < 0) continue;
    double *d = &sys.block_values[9 * sys.diagonal_block[p]];
    for (int k = 0; k < 9; ++k) d[k] = 0.0;
    d[0] = d[4] = d[8] = cloth.mass[p];
    for (int k = 0; k < 3; ++k) sys.rhs[3 * p + k] = h * cloth.mass[p] * cloth.gravity[k];
  }
  // Springs go in chunks: first every spring's terms (square root and divisions), one vector lane per spring,
  // then the sums into blocks and right-hand side, spring by spring. In one pass the stores of one spring
  // stood between the loads of the next and the loop ran at the latency of the square root.
  static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "positions are read as packed triples");
  constexpr int chunk = 64;
  double        rest[chunk], stiffness[chunk], sep[3][chunk], rel[3][chunk], dir[3][chunk], force[3][chunk],
    k_iso[chunk], k_dir[chunk];
  const double *x       = reinterpret_cast<const double *>(cloth.position.data()),
               *v       = reinterpret_cast<const double *>(cloth.velocity.data());
  const Spring *springs = cloth.springs.data();
  const double  damping = cloth.damping;
  const bool    choi_ko = params.choi_ko;
  for (size_t s0 = 0; s0 < sys.springs.size(); s0 += chunk) {
    const int  n   = (int)std::min(sys.springs.size() - s0, (size_t)chunk);
    const int *idx = sys.springs.data() + s0;
    for (int i = 0; i < n;
         ++i) { // the chunk's inputs side by side: GCC 12 does not gather them for the vector loop below
      const Spring &sp = springs[idx[i]];
      rest[i] = sp.rest_length, stiffness[i] = sp.stiffness;
      for (int k = 0; k < 3; ++k) {
        sep[k][i] = x[3 * sp.b + k] - x[3 * sp.a + k];
        rel[k][i] = v[3 * sp.b + k] - v[3 * sp.a + k];
      }
    }
#pragma omp simd
    for (int i = 0; i < n; ++i)
      spring_terms_lane(rest[i], stiffness[i], sep[0][i], sep[1][i], sep[2][i], rel[0][i], rel[1][i],
                        rel[2][i], damping, choi_ko, dir[0][i], dir[1][i], dir[2][i], force[0][i],
                        force[1][i], force[2][i], k_iso[i], k_dir[i]);
    for (int i = 0; i < n; ++i) {
      SpringTerms t;
      t.direction  = Eigen::Vector3d(dir[0][i], dir[1][i], dir[2][i]);
      t.force_on_a = Eigen::Vector3d(force[0][i], force[1][i], force[2][i]);
      t.k_iso = k_iso[i], t.k_dir = k_dir[i], t.damping = damping;
      add_spring(cloth, sys, springs[idx[i]], t, h, sys.block_ab[s0 + i], sys.block_ba[s0 + i]);
    }
  }
  for (int p = 0; p < sys.n_particles; ++p)
    if (cloth.fixed[p])
      for (int k = 0; k < 3; ++k) sys.rhs[3 * p + k] = 0;
}

void cloth_forces(const Cloth &cloth, std::vector<Eigen::Vector3d> &forces)
{
  forces.resize(cloth.particle_count());
  for (int p = 0; p < cloth.particle_count(); ++p) forces[p] = cloth.mass[p] * cloth.gravity;
  for (const Spring &sp : cloth.springs) {
    const SpringLinearisation lin =
      linearise_spring(sp, cloth.position[sp.a], cloth.position[sp.b], cloth.velocity[sp.a],
                       cloth.velocity[sp.b], cloth.damping);
    forces[sp.a] += lin.force_on_a;
    forces[sp.b] -= lin.force_on_a;
  }
  for (int p = 0; p < cloth.particle_count(); ++p)
    if (cloth.fixed[p]) forces[p].setZero();
}

ClothStepReport cloth_step(Cloth &cloth, ClothSystem &sys, const ClothParams &params,
                           const BlockLinearSolver &solver)
{
  ClothStepReport report;
  assemble_cloth_system(cloth, params, sys);
  solver.set_matrix(sys.block_values);
  const LinearSolveResult r =
    solver.solve(sys.rhs, sys.dv); // sys.dv: last step's dv, a warm start if asked for
  report.iterations = r.iterations;
  report.converged  = r.converged;
  report.breakdown  = r.breakdown;
  const double h    = params.dt;
  for (int p = 0; p < sys.n_particles; ++p) {
    if (cloth.fixed[p]) continue;
    cloth.velocity[p] += Eigen::Vector3d(sys.dv[3 * p], sys.dv[3 * p + 1], sys.dv[3 * p + 2]);
    cloth.position[p] += h * cloth.velocity[p];
  }
  for (int p = 0; p < sys.n_particles; ++p) {
    if (cloth.fixed[p]) continue;
    if (cloth.sphere.enabled) {
      const Eigen::Vector3d d    = cloth.position[p] - cloth.sphere.centre;
      const double          dist = d.norm();
      if (dist < cloth.sphere.radius && dist > 0) {
        const Eigen::Vector3d normal = d / dist;
        cloth.position[p]            = cloth.sphere.centre + cloth.sphere.radius * normal;
        const double vn              = cloth.velocity[p].dot(normal);
        if (vn < 0) cloth.velocity[p] -= vn * normal;
        report.contacts++;
      }
    }
  }
  const double            t0      = params.clock ? params.clock() : 0.0;
  const StrainLimitReport limited = limit_strain(cloth, sys.strain_limiter, params.strain_limit, h);
  report.strain_seconds           = params.clock ? params.clock() - t0 : 0.0;
  report.strain_sweeps            = limited.sweeps;
  report.strain_capped            = limited.capped;
  // the limiting measured the largest stretch over every stretch spring (every process holds the
  // whole cloth): no second pass, on any number of processes; without it, this process's own springs
  report.max_stretch = limited.sweeps > 0 ? limited.max_ratio : max_stretch_ratio(cloth, sys.stretch_springs);
  return report;
}

} // namespace physics
