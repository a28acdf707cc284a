// The quadratic (10-node) tetrahedron kernel, in the style of element_kernels.hpp (included from
// there). No stored K0: every block and force is formed from the 4 barycentric gradients.
//
// With straight edges the shape-function gradients are affine in the barycentric coordinates L and
// combinations of the corner gradients g_c: corner a: (4 L_a - 1) g_a; edge (i, j): 4 L_j g_i + 4 L_i g_j.
// Writing grad N_a = sum_c phi_ac(L) g_c, the element stiffness is exactly
//   K0_ab = V sum_cd E[phi_ac phi_bd] Q_cd,   Q_cd = lambda g_c g_d^T + mu g_d g_c^T + mu (g_c . g_d) I,
// E the mean over the element (E[L_i] = 1/4, E[L_i L_j] = (1 + [i = j]) / 20), and R K0_ab R^T is the
// same sum over the rotated Q_cd (g -> R g). The coefficients: corner-corner 3/5 (a = b) or -1/5;
// corner a with edge (i, j): 3/5 on Q_ai if a = j else -1/5, likewise Q_aj; edge-edge 4/5 (1 + [..])
// on the four cross pairs. That is 142 terms of 3x3 for the 55 upper blocks, against 55 rotations
// R K R^T of stored blocks (about half the flops, and no 4 KB of K0 per element to read).
//
// The force: the displacement gradient G(L) = sum_b z_b grad N_b^T is affine, G(L) = sum_k L_k G_k
// with G_k its value at corner k, G_k = sum_d w_kd g_d^T, w_kk = 3 z_k, w_kd = 4 z_(edge dk) - z_d;
// so is the stress, and sum_b K0_ab z_b = V E[sigma grad N_a] = V sum_c sum_k E[phi_ac L_k] sigma_k g_c
// with E[(4 L_a - 1) L_k] = 3/20 (k = a) or -1/20, E[4 L_j L_k] = 2/5 (k = j) or 1/5.
#pragma once

namespace physics {
namespace kernels {
inline namespace BINBCSR_ELEMENT_SET {

// Corners of the edge nodes 4..9 (tet_mesh.hpp's kTetEdges) and the edge of a corner pair.
constexpr int kP2EdgeCorners[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
constexpr int kP2EdgeOf[4][4]      = {{-1, 0, 2, 3}, {0, -1, 1, 4}, {2, 1, -1, 5}, {3, 4, 5, -1}};

// The terms of block p (packed upper pair (a, b) of the 10 nodes): B_ab = sum_t coef_t Q_(cd_t) with
// Q_cd at cd = 4 c + d (all 16 pairs stored, Q_dc = Q_cd^T); blocks with fewer than 4 terms are padded
// with zero coefficients, so every block runs the same code (the lane loop is then one body for all
// blocks with the block number uniform across the lanes: a fully unrolled 55-block body was left
// scalar by GCC).
struct P2BlockTerms {
  int    a[55], b[55], cd[55][4];
  double coef[55][4];
  constexpr P2BlockTerms() : a(), b(), cd(), coef()
  {
    int p = 0;
    for (int i = 0; i < 10; ++i)
      for (int j = i; j < 10; ++j, ++p) {
        a[p] = i, b[p] = j;
        int  n   = 0;
        auto add = [&](int c, int d, double w) { cd[p][n] = 4 * c + d, coef[p][n] = w, ++n; };
        if (j < 4) { // corner-corner
          add(i, j, i == j ? 3.0 / 5 : -1.0 / 5);
        } else if (i < 4) { // corner-edge
          const int e0 = kP2EdgeCorners[j - 4][0], e1 = kP2EdgeCorners[j - 4][1];
          add(i, e0, i == e1 ? 3.0 / 5 : -1.0 / 5);
          add(i, e1, i == e0 ? 3.0 / 5 : -1.0 / 5);
        } else { // edge-edge
          const int e0 = kP2EdgeCorners[i - 4][0], e1 = kP2EdgeCorners[i - 4][1];
          const int f0 = kP2EdgeCorners[j - 4][0], f1 = kP2EdgeCorners[j - 4][1];
          add(e0, f0, e1 == f1 ? 8.0 / 5 : 4.0 / 5);
          add(e0, f1, e1 == f0 ? 8.0 / 5 : 4.0 / 5);
          add(e1, f0, e0 == f1 ? 8.0 / 5 : 4.0 / 5);
          add(e1, f1, e0 == f0 ? 8.0 / 5 : 4.0 / 5);
        }
        while (n < 4) add(0, 0, 0.0);
      }
  }
};
constexpr P2BlockTerms kP2Blocks{};

// The gradient of a quadratic field at corner kk of the tetrahedron, G (3 x 3, row-major) =
// sum_d w_d g_d^T with w_d = 3 u_d at d = kk, else 4 u_(edge d-kk) - u_d (u: the 10 nodal values,
// g: the barycentric gradients). The forces take it of the displacements with damping, the energy of
// the displacements.
BINBCSR_PHYS_HD void p2_corner_gradient(const double (*u)[3], const double (*g)[3], int kk, double *G)
{
  BINBCSR_PHYS_UNROLL
  for (int j = 0; j < 9; ++j) G[j] = 0;
  BINBCSR_PHYS_UNROLL
  for (int d = 0; d < 4; ++d) {
    double w[3];
    BINBCSR_PHYS_UNROLL
    for (int i = 0; i < 3; ++i) w[i] = kk == d ? 3.0 * u[d][i] : 4.0 * u[4 + kP2EdgeOf[d][kk]][i] - u[d][i];
    BINBCSR_PHYS_UNROLL
    for (int i = 0; i < 3; ++i) BINBCSR_PHYS_UNROLL
    for (int j = 0; j < 3; ++j) G[3 * i + j] += w[i] * g[d][j];
  }
}

// One quadratic tetrahedron's forces: rhs (30) = -R sum_b K0_ab z_b - a_M m sum_b Mref_ab v_b, m = rho V;
// Mref: 10 x 10 reference mass.
template <int S, bool MassDamping>
BINBCSR_PHYS_HD void p2_forces(const double *x, const double *v, const double *X, const double *Dinv,
                               const double *R, double vol, const ElementConstants &k, const double *Mref,
                               double *rhs)
{
  double g[4][3], z[10][3];
  barycentric_gradients<S>(Dinv, g);
  rest_frame_displacements<S, 10>(x, v, X, R, k, z);
  // sigma_kk g_c for the stress at each corner kk.
  double y[4][4][3];
  BINBCSR_PHYS_UNROLL
  for (int kk = 0; kk < 4; ++kk) {
    double G[9];
    p2_corner_gradient(z, g, kk, G);
    double sigma[9];
    linear_stress(G, k.lambda, k.mu, sigma);
    BINBCSR_PHYS_UNROLL
    for (int c = 0; c < 4; ++c) BINBCSR_PHYS_UNROLL
    for (int i = 0; i < 3; ++i)
      y[kk][c][i] = sigma[3 * i] * g[c][0] + sigma[3 * i + 1] * g[c][1] + sigma[3 * i + 2] * g[c][2];
  }
  const double m = k.density * vol;
  BINBCSR_PHYS_UNROLL
  for (int a = 0; a < 10; ++a) {
    double s[3] = {0, 0, 0};
    BINBCSR_PHYS_UNROLL
    for (int kk = 0; kk < 4; ++kk) BINBCSR_PHYS_UNROLL
    for (int i = 0; i < 3; ++i) {
      if (a < 4) {
        s[i] += (kk == a ? 3.0 / 20 : -1.0 / 20) * y[kk][a][i];
      } else {
        const int ci = kP2EdgeCorners[a - 4][0], cj = kP2EdgeCorners[a - 4][1];
        s[i] += (kk == cj ? 2.0 / 5 : 1.0 / 5) * y[kk][ci][i] + (kk == ci ? 2.0 / 5 : 1.0 / 5) * y[kk][cj][i];
      }
    }
    double f[3];
    rotate<S>(R, s, f);
    BINBCSR_PHYS_UNROLL
    for (int d = 0; d < 3; ++d) {
      double mv = 0;
      if (MassDamping) {
        BINBCSR_PHYS_UNROLL
        for (int b = 0; b < 10; ++b) mv += Mref[10 * a + b] * v[(3 * b + d) * S];
      }
      rhs[(3 * a + d) * S] = -vol * f[d] - k.mass_rhs * m * mv;
    }
  }
}

// Its rotated gradient pairs Q_cd (16 x 9, row-major, at (9 (4 c + d) + e) S), scaled by c_K V.
template <int S>
BINBCSR_PHYS_HD void p2_gradient_pairs(const double *Dinv, const double *R, double vol,
                                       const ElementConstants &k, double *Q)
{
  double g[4][3], rg[4][3];
  barycentric_gradients<S>(Dinv, g);
  BINBCSR_PHYS_UNROLL
  for (int c = 0; c < 4; ++c) rotate<S>(R, g[c], rg[c]);
  const double kv = k.stiffness_matrix * vol, kl = kv * k.lambda, km = kv * k.mu;
  BINBCSR_PHYS_UNROLL
  for (int c = 0; c < 4; ++c) BINBCSR_PHYS_UNROLL
  for (int d = 0; d < 4; ++d) {
    const double diag = km * (g[c][0] * g[d][0] + g[c][1] * g[d][1] + g[c][2] * g[d][2]);
    BINBCSR_PHYS_UNROLL
    for (int i = 0; i < 3; ++i) BINBCSR_PHYS_UNROLL
    for (int j = 0; j < 3; ++j)
      Q[(9 * (4 * c + d) + 3 * i + j) * S] =
        kl * rg[c][i] * rg[d][j] + km * rg[d][i] * rg[c][j] + (i == j ? diag : 0.0);
  }
}

// Block p of its 55 upper blocks: c_K R K0_ab R^T + c_M m Mref_ab I, m = rho V, from the pairs Q.
template <int S>
BINBCSR_PHYS_HD void p2_block(int p, const double *Q, double vol, const ElementConstants &k,
                              const double *Mref, double *block)
{
  double B[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  BINBCSR_PHYS_UNROLL
  for (int t = 0; t < 4; ++t) {
    const double  w = kP2Blocks.coef[p][t];
    const double *q = Q + 9 * kP2Blocks.cd[p][t] * S;
    BINBCSR_PHYS_UNROLL
    for (int e = 0; e < 9; ++e) B[e] += w * q[e * S];
  }
  const double mass = k.mass_matrix * k.density * vol * Mref[10 * kP2Blocks.a[p] + kP2Blocks.b[p]];
  BINBCSR_PHYS_UNROLL
  for (int e = 0; e < 9; ++e) block[e * S] = B[e] + (e % 4 == 0 ? mass : 0.0);
}

// Its elastic energy u^T K0 u / 2, u_b = R^T x_b - X_b: V E[sigma(G(L)) : G(L)] / 2 with the affine
// displacement gradient G(L) = sum_k L_k G_k (G_k at corner k, as in p2_forces) and
// E[L_i L_j] = (1 + [i = j]) / 20, i.e. V / 40 (sum_k sigma(G_k) : G_k + sigma(sum_k G_k) : sum_k G_k)
// (the stored K0's 4-point rule is exact for this quadratic integrand, so both are the same sum).
template <int S>
BINBCSR_PHYS_HD double p2_elastic_energy(const double *x, const double *X, const double *Dinv,
                                         const double *R, double vol, double lambda, double mu)
{
  double g[4][3], u[10][3];
  barycentric_gradients<S>(Dinv, g);
  rest_frame_displacement<S, 10>(x, X, R, u);
  double Gsum[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, corners = 0;
  BINBCSR_PHYS_UNROLL
  for (int kk = 0; kk < 4; ++kk) {
    double G[9];
    p2_corner_gradient(u, g, kk, G);
    corners += strain_product(G, G, lambda, mu);
    BINBCSR_PHYS_UNROLL
    for (int j = 0; j < 9; ++j) Gsum[j] += G[j];
  }
  return vol / 40 * (corners + strain_product(Gsum, Gsum, lambda, mu));
}

// Both, for a caller that owns one element (S = 1, a GPU thread).
template <int S, bool Blocks, bool MassDamping>
BINBCSR_PHYS_HD void p2_element(const double *x, const double *v, const double *X, const double *Dinv,
                                const double *R, double vol, const ElementConstants &k, const double *Mref,
                                double *rhs, double *blocks)
{
  p2_forces<S, MassDamping>(x, v, X, Dinv, R, vol, k, Mref, rhs);
  if (!Blocks) return;
  double Q[16 * 9 * S];
  p2_gradient_pairs<S>(Dinv, R, vol, k, Q);
  for (int p = 0; p < 55; ++p) p2_block<S>(p, Q, vol, k, Mref, blocks + 9 * p * S);
}

} // namespace BINBCSR_ELEMENT_SET
} // namespace kernels
} // namespace physics
