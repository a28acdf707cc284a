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

// Corners of the edge nodes 4..9 (tet_mesh.hpp's kTetEdges) and the edge of a corner pair.
constexpr int kP2EdgeCorners[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
constexpr int kP2EdgeOf[4][4]      = {{-1, 0, 2, 3}, {0, -1, 1, 4}, {2, 1, -1, 5}, {3, 4, 5, -1}};

// B += coef Q_cd, with Q_dc = Q_cd^T and only c <= d stored (Q[packed (c, d)], row-major).
BINBCSR_PHYS_HD void add_gradient_pair(double B[9], const double Q[10][9], int c, int d, double coef)
{
  const int lo = c < d ? c : d, hi = c < d ? d : c, q = lo * 4 - lo * (lo - 1) / 2 + (hi - lo);
  BINBCSR_PHYS_UNROLL
  for (int i = 0; i < 3; ++i)
    BINBCSR_PHYS_UNROLL
    for (int j = 0; j < 3; ++j) B[3 * i + j] += coef * (c <= d ? Q[q][3 * i + j] : Q[q][3 * j + i]);
}

// One quadratic tetrahedron: rhs (30) = -R sum_b K0_ab z_b - a_M m sum_b Mref_ab v_b, blocks (55 x 9,
// when Blocks) = c_K R K0_ab R^T + c_M m Mref_ab I, m = rho V; Mref: 10 x 10 reference mass.
template <int S, bool Blocks, bool MassDamping>
BINBCSR_PHYS_HD void p2_element(const double *x, const double *v, const double *X, const double *Dinv, const double *R,
                                double vol, const ElementConstants &k, const double *Mref, double *rhs, double *blocks)
{
  double g[4][3], z[10][3];
  barycentric_gradients<S>(Dinv, g);
  rest_frame_displacements<S, 10>(x, v, X, R, k, z);
  // sigma_kk g_c for the stress at each corner kk.
  double y[4][4][3];
  BINBCSR_PHYS_UNROLL
  for (int kk = 0; kk < 4; ++kk) {
    double G[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    BINBCSR_PHYS_UNROLL
    for (int d = 0; d < 4; ++d) {
      double w[3];
      BINBCSR_PHYS_UNROLL
      for (int i = 0; i < 3; ++i) w[i] = kk == d ? 3.0 * z[d][i] : 4.0 * z[4 + kP2EdgeOf[d][kk]][i] - z[d][i];
      BINBCSR_PHYS_UNROLL
      for (int i = 0; i < 3; ++i)
        BINBCSR_PHYS_UNROLL
        for (int j = 0; j < 3; ++j) G[3 * i + j] += w[i] * g[d][j];
    }
    double sigma[9];
    linear_stress(G, k.lambda, k.mu, sigma);
    BINBCSR_PHYS_UNROLL
    for (int c = 0; c < 4; ++c)
      BINBCSR_PHYS_UNROLL
      for (int i = 0; i < 3; ++i) y[kk][c][i] = sigma[3 * i] * g[c][0] + sigma[3 * i + 1] * g[c][1] + sigma[3 * i + 2] * g[c][2];
  }
  const double m = k.density * vol;
  BINBCSR_PHYS_UNROLL
  for (int a = 0; a < 10; ++a) {
    double s[3] = {0, 0, 0};
    BINBCSR_PHYS_UNROLL
    for (int kk = 0; kk < 4; ++kk)
      BINBCSR_PHYS_UNROLL
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
  if (!Blocks) return;
  // Rotated Q_cd, c <= d, scaled by c_K V.
  double rg[4][3], Q[10][9];
  BINBCSR_PHYS_UNROLL
  for (int c = 0; c < 4; ++c) rotate<S>(R, g[c], rg[c]);
  const double kv = k.stiffness_matrix * vol, kl = kv * k.lambda, km = kv * k.mu;
  int          q  = 0;
  BINBCSR_PHYS_UNROLL
  for (int c = 0; c < 4; ++c)
    BINBCSR_PHYS_UNROLL
    for (int d = c; d < 4; ++d, ++q) {
      const double diag = km * (g[c][0] * g[d][0] + g[c][1] * g[d][1] + g[c][2] * g[d][2]);
      BINBCSR_PHYS_UNROLL
      for (int i = 0; i < 3; ++i)
        BINBCSR_PHYS_UNROLL
        for (int j = 0; j < 3; ++j) Q[q][3 * i + j] = kl * rg[c][i] * rg[d][j] + km * rg[d][i] * rg[c][j] + (i == j ? diag : 0.0);
    }
  int p = 0;
  BINBCSR_PHYS_UNROLL
  for (int a = 0; a < 10; ++a)
    BINBCSR_PHYS_UNROLL
    for (int b = a; b < 10; ++b, ++p) {
      double B[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
      if (b < 4) { // corner-corner
        add_gradient_pair(B, Q, a, b, a == b ? 3.0 / 5 : -1.0 / 5);
      } else if (a < 4) { // corner-edge
        const int i = kP2EdgeCorners[b - 4][0], j = kP2EdgeCorners[b - 4][1];
        add_gradient_pair(B, Q, a, i, a == j ? 3.0 / 5 : -1.0 / 5);
        add_gradient_pair(B, Q, a, j, a == i ? 3.0 / 5 : -1.0 / 5);
      } else { // edge-edge
        const int i = kP2EdgeCorners[a - 4][0], j = kP2EdgeCorners[a - 4][1];
        const int e = kP2EdgeCorners[b - 4][0], f = kP2EdgeCorners[b - 4][1];
        add_gradient_pair(B, Q, i, e, j == f ? 8.0 / 5 : 4.0 / 5);
        add_gradient_pair(B, Q, i, f, j == e ? 8.0 / 5 : 4.0 / 5);
        add_gradient_pair(B, Q, j, e, i == f ? 8.0 / 5 : 4.0 / 5);
        add_gradient_pair(B, Q, j, f, i == e ? 8.0 / 5 : 4.0 / 5);
      }
      const double mass = k.mass_matrix * m * Mref[10 * a + b];
      BINBCSR_PHYS_UNROLL
      for (int j = 0; j < 9; ++j) blocks[(9 * p + j) * S] = B[j] + (j % 4 == 0 ? mass : 0.0);
    }
}

} // namespace kernels
} // namespace physics
