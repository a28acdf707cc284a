// Corotational tetrahedron kernels as per-element functions over plain arrays: the deformation
// gradient, the rotation (polar factor) by a fixed number of Newton steps, and the P1 / P2 element
// (rotated stiffness blocks and corotational forces). No allocation, no Eigen, no STL, no PETSc, so
// that a GPU can run one element per thread (BINBCSR_PHYS_HD becomes __host__ __device__ under nvcc).
//
// Layout: entry k of an element's array is at p[k * S]. The CPU (element_batch_body.hpp) keeps a
// batch of S elements as structure of arrays and calls the functions from an `omp simd` loop over the
// lanes, with the pointers offset by the lane, so every access is a contiguous vector across the
// lanes; a thread that owns one element calls them with S = 1. The bodies have no data-dependent branches
// (selects only) and fixed trip counts, which the compiler unrolls inside the lane loop.
//
// Conventions: 3x3 matrices F, R, Dm^-1 column-major (Eigen's order: (r, c) at 3 c + r); nodal
// vectors node-major (node b, component d at 3 b + d); output blocks row-major ((r, c) at 3 r + c),
// block (a, b), a <= b, at 9 * packed index (row by row over the upper triangle, fem_model.hpp).
#pragma once
#include <cmath>

#if defined(__CUDACC__)
  #define BINBCSR_PHYS_HD     __host__ __device__ __forceinline__
  #define BINBCSR_PHYS_UNROLL _Pragma("unroll")
#else
  #define BINBCSR_PHYS_HD     inline __attribute__((always_inline))
  #define BINBCSR_PHYS_UNROLL _Pragma("GCC unroll 64")
#endif

// The functions below are compiled once per body set (element_batch.hpp: portable, avx2, avx512, each
// translation unit with its own target flags) and live in an inline namespace named after the set, so
// the AVX-512 copy of an inline function can never stand in for the baseline one at link time. A file
// that defines no set (the scalar code, the tests) gets `baseline`.
#if !defined(BINBCSR_ELEMENT_SET)
  #define BINBCSR_ELEMENT_SET baseline
#endif

namespace physics {
namespace kernels {

// What every element of a call shares: the integrator's coefficients (corotational_assembly.hpp) and
// the material. (Data only: one type for every body set.)
struct ElementConstants {
  double force, stiffness_rhs, mass_rhs, mass_matrix, stiffness_matrix; // a_f, a_K, a_M, c_M, c_K
  double lambda, mu, density;
};

inline namespace BINBCSR_ELEMENT_SET {

// ---- deformation gradient -------------------------------------------------------------------------

// F = Ds Dm^-1, Ds = (x1 - x0, x2 - x0, x3 - x0) from the corner positions xc (node-major, 12 entries).
template <int S> BINBCSR_PHYS_HD void deformation_gradient(const double *xc, const double *Dinv, double *F)
{
  double Ds[9];
  BINBCSR_PHYS_UNROLL
  for (int k = 0; k < 3; ++k) BINBCSR_PHYS_UNROLL
  for (int r = 0; r < 3; ++r) Ds[3 * k + r] = xc[(3 * (k + 1) + r) * S] - xc[r * S];
  BINBCSR_PHYS_UNROLL
  for (int c = 0; c < 3; ++c) BINBCSR_PHYS_UNROLL
  for (int r = 0; r < 3; ++r)
    F[(3 * c + r) * S] =
      Ds[r] * Dinv[(3 * c) * S] + Ds[3 + r] * Dinv[(3 * c + 1) * S] + Ds[6 + r] * Dinv[(3 * c + 2) * S];
}

// ---- rotation -------------------------------------------------------------------------------------

// The limits of polar_decomposition.cpp's Newton iteration (the scalar reference): an iterate is
// accepted when its last step changed it by less than 1e-7 (so it is within ~1e-14 of the limit) and
// |det - 1| < 1e-8; a start with det(F / |F| sqrt 3) <= 5.2e-6 (inverted, flat) is not iterated.
constexpr double kPolarMinStartDet  = 5.2e-6;
constexpr double kPolarConverged2   = 1e-14;
constexpr double kPolarDetTolerance = 1e-8;
// Newton steps, all lanes alike, the first kPolarScaledSteps with Higham's Frobenius scaling (two
// square roots and a division more, on the lanes' latency chain). Steps needed to pass the acceptance
// test (20,000 random F per row): singular value ratios up to 1.02: 3; 1.5: 4; 4: 5; 10: 6, so 5 steps
// pass every element stretched up to 4:1 and most at 10:1; the rest take the scalar path. Steps
// after convergence keep the iterate (a rotation is a fixed point). A batch whose lanes all pass after
// kPolarEarlySteps stops there (element_batch_body.hpp): the scenes' elements are strained by a few
// percent at most, and the two steps saved were ~5% of linear_38k's element loop.
constexpr int kPolarSteps       = 5;
constexpr int kPolarScaledSteps = 2;
constexpr int kPolarEarlySteps  = 3;
// The start X = F sqrt 3 / |F| has |X|^2 = 3, so det X <= 1, with 1 - det X ~ (sum of the squared
// deviations of its singular values from 1) / 2. Where det X > kPolarNearDet they are within ~3% of 1:
// Newton's steps need no scaling there (the deviation d goes to ~d^2 / 2 per step, so after three the
// change is below 1e-7), and a batch of such lanes skips the two scaled steps' square roots and
// division, which lie on the lanes' latency chain.
constexpr double kPolarNearDet = 0.9996;

// Columns of cof(X) = det(X) X^-T (cross products of X's other two columns) and det X. T: double for
// one element, or a lane packet (polar_decomposition.cpp's batched Newton iteration).
template <class T> BINBCSR_PHYS_HD void cofactor3(const T *X, T *C, T &det)
{
  C[0] = X[4] * X[8] - X[5] * X[7];
  C[1] = X[5] * X[6] - X[3] * X[8];
  C[2] = X[3] * X[7] - X[4] * X[6];
  C[3] = X[7] * X[2] - X[8] * X[1];
  C[4] = X[8] * X[0] - X[6] * X[2];
  C[5] = X[6] * X[1] - X[7] * X[0];
  C[6] = X[1] * X[5] - X[2] * X[4];
  C[7] = X[2] * X[3] - X[0] * X[5];
  C[8] = X[0] * X[4] - X[1] * X[3];
  det  = X[0] * C[0] + X[1] * C[1] + X[2] * C[2];
}

// Dm^-1 = cof(Dm)^T / det Dm and the rest volume det Dm / 6, Dm = (X1 - X0, X2 - X0, X3 - X0), from the
// corner rest positions Xc (node-major): tet_geometry's values up to rounding. The batched loop
// computes them from the rest positions it gathers anyway rather than reading the model's 80 bytes
// per element (4.8 MB per pass for linear_38k), which cost more than these ~50 flops per lane.
template <int S> BINBCSR_PHYS_HD void rest_shape(const double *Xc, double *Dinv, double *volume)
{
  double Dm[9], C[9], det;
  BINBCSR_PHYS_UNROLL
  for (int k = 0; k < 3; ++k) BINBCSR_PHYS_UNROLL
  for (int r = 0; r < 3; ++r) Dm[3 * k + r] = Xc[(3 * (k + 1) + r) * S] - Xc[r * S];
  cofactor3(Dm, C, det);
  const double inverse_det = 1.0 / det;
  BINBCSR_PHYS_UNROLL
  for (int c = 0; c < 3; ++c) BINBCSR_PHYS_UNROLL
  for (int r = 0; r < 3; ++r) Dinv[(3 * c + r) * S] = C[3 * r + c] * inverse_det;
  *volume = det / 6.0;
}

// The polar factor of F by scaled Newton steps X <- (g X + cof(X) / (g det X)) / 2, without branches,
// in three pieces so that a batch can stop early: polar_start, polar_steps, polar_finish. The
// iteration's state (X, cof X, det X, the lane's flag ok, the last step's change) lives at stride T:
// registers for one call of polar_rotation, the batch's arrays between the pieces.
//
// The lane's flags are doubles (1 or 0), combined by products, and every choice a select: with bool
// flags GCC mixed mask widths it could not vectorise, and without -fno-trapping-math (set for the
// batch bodies, CMakeLists.txt) it kept the selects as branches; either left the lane loop scalar
// (a Zen 3 core: linear_38k's element loop 21 ms, 14.2-14.6 ms vectorised).

// The start X = F sqrt(3) / |F|; a lane that cannot start (inverted, flat, zero, Inf or NaN) gets
// ok = 0 and runs on the identity, which stays put.
template <int S, int T>
BINBCSR_PHYS_HD void polar_start(const double *F, double *Xs, double *Cs, double *dets, double *oks)
{
  double X[9], C[9], det, s2 = 0;
  BINBCSR_PHYS_UNROLL
  for (int j = 0; j < 9; ++j) s2 += F[j * S] * F[j * S];
  const double finite = (s2 > 0 ? 1.0 : 0.0) * (s2 < 1e300 ? 1.0 : 0.0); // 0 for 0, Inf and NaN
  const double k      = std::sqrt(3.0 / (finite != 0 ? s2 : 3.0));
  BINBCSR_PHYS_UNROLL
  for (int j = 0; j < 9; ++j) {
    const double f = F[j * S];
    X[j]           = finite != 0 ? f * k : (j % 4 == 0 ? 1.0 : 0.0);
  }
  cofactor3(X, C, det);
  const double ok = finite * (det > kPolarMinStartDet ? 1.0 : 0.0);
  BINBCSR_PHYS_UNROLL
  for (int j = 0; j < 9; ++j) {
    Xs[j * T] = ok != 0 ? X[j] : (j % 4 == 0 ? 1.0 : 0.0);
    Cs[j * T] = ok != 0 ? C[j] : (j % 4 == 0 ? 1.0 : 0.0);
  }
  *dets = ok != 0 ? det : 1.0;
  *oks  = ok;
}

// Newton steps First .. Last - 1 (the first Scaled of the whole iteration scaled); *change: the last
// step's squared change.
template <int T, int First, int Last, int Scaled = kPolarScaledSteps>
BINBCSR_PHYS_HD void polar_steps(double *Xs, double *Cs, double *dets, double *oks, double *changes)
{
  double X[9], C[9], det = *dets, ok = *oks, change = 0;
  BINBCSR_PHYS_UNROLL
  for (int j = 0; j < 9; ++j) X[j] = Xs[j * T], C[j] = Cs[j * T];
  BINBCSR_PHYS_UNROLL
  for (int it = First; it < Last; ++it) {
    double g = 1;
    if (it < Scaled) { // a constant condition: resolved when the loop is unrolled
      double x2 = 0, c2 = 0;
      BINBCSR_PHYS_UNROLL
      for (int j = 0; j < 9; ++j) x2 += X[j] * X[j], c2 += C[j] * C[j];
      g = std::sqrt(std::sqrt(c2 / (det * det * x2))); // (|X^-1| / |X|)^(1/2), |X^-1| = |cof X| / |det X|
    }
    const double a = 0.5 * g, b = 0.5 / (g * det);
    change = 0;
    BINBCSR_PHYS_UNROLL
    for (int j = 0; j < 9; ++j) {
      const double next = a * X[j] + b * C[j];
      change += (next - X[j]) * (next - X[j]);
      X[j] = next;
    }
    cofactor3(X, C, det);
    ok *= (det > 0 ? 1.0 : 0.0) * (det < 1e300 ? 1.0 : 0.0);
    det = ok != 0 ? det : 1.0; // the lane is lost; keep its arithmetic finite
  }
  BINBCSR_PHYS_UNROLL
  for (int j = 0; j < 9; ++j) Xs[j * T] = X[j], Cs[j * T] = C[j];
  *dets = det, *oks = ok, *changes = change;
}

// 1 where the iterate passes the acceptance test (its last step changed it by less than 1e-7 and |det -
// 1| < 1e-8), else 0.
BINBCSR_PHYS_HD double polar_accepted(double det, double ok, double change)
{
  return ok * (change < kPolarConverged2 ? 1.0 : 0.0) *
         (std::fabs(det - 1.0) < kPolarDetTolerance ? 1.0 : 0.0);
}

// R = X where accepted, else the identity.
template <int S, int T> BINBCSR_PHYS_HD void polar_finish(const double *Xs, double accepted, double *R)
{
  BINBCSR_PHYS_UNROLL
  for (int j = 0; j < 9; ++j) R[j * S] = accepted != 0 ? Xs[j * T] : (j % 4 == 0 ? 1.0 : 0.0);
}

// R = polar factor of F by kPolarSteps steps. Returns 1 where R passed the acceptance test, 0 where the
// caller must take the scalar path (rotation_from_deformation: inverted or flat elements get the
// sign-corrected SVD rotation, broken F the identity). R is then the identity, and no lane divides by
// zero or makes NaN on the way. (A double, not a flag type: in the lane loop a 32-bit result would
// halve the vector width.)
template <int S> BINBCSR_PHYS_HD double polar_rotation(const double *F, double *R)
{
  double X[9], C[9], det, ok, change;
  polar_start<S, 1>(F, X, C, &det, &ok);
  polar_steps<1, 0, kPolarSteps>(X, C, &det, &ok, &change);
  const double accepted = polar_accepted(det, ok, change);
  polar_finish<S, 1>(X, accepted, R);
  return accepted;
}

// ---- shared element pieces ------------------------------------------------------------------------

// Barycentric gradients g_a (4 x 3, node-major) from Dm^-1: g_{k+1} = row k, g_0 = -(g_1 + g_2 + g_3).
template <int S> BINBCSR_PHYS_HD void barycentric_gradients(const double *Dinv, double g[4][3])
{
  BINBCSR_PHYS_UNROLL
  for (int d = 0; d < 3; ++d) {
    BINBCSR_PHYS_UNROLL
    for (int k = 0; k < 3; ++k) g[k + 1][d] = Dinv[(3 * d + k) * S];
    g[0][d] = -(g[1][d] + g[2][d] + g[3][d]);
  }
}

// z_b = R^T (a_f x_b + a_K v_b) - a_f X_b for n nodes: the displacement in the element's rest frame
// (plus the stiffness-damping velocity term), so that rhs_a = -R sum_b K0_ab z_b in one pass.
template <int S, int N>
BINBCSR_PHYS_HD void rest_frame_displacements(const double *x, const double *v, const double *X,
                                              const double *R, const ElementConstants &k, double z[N][3])
{
  BINBCSR_PHYS_UNROLL
  for (int b = 0; b < N; ++b) {
    double y[3];
    BINBCSR_PHYS_UNROLL
    for (int d = 0; d < 3; ++d) y[d] = k.force * x[(3 * b + d) * S] + k.stiffness_rhs * v[(3 * b + d) * S];
    BINBCSR_PHYS_UNROLL
    for (int i = 0; i < 3; ++i)
      z[b][i] = R[(3 * i) * S] * y[0] + R[(3 * i + 1) * S] * y[1] + R[(3 * i + 2) * S] * y[2] -
                k.force * X[(3 * b + i) * S];
  }
}

// r = R g (R column-major at stride S).
template <int S> BINBCSR_PHYS_HD void rotate(const double *R, const double g[3], double r[3])
{
  BINBCSR_PHYS_UNROLL
  for (int i = 0; i < 3; ++i) r[i] = R[i * S] * g[0] + R[(3 + i) * S] * g[1] + R[(6 + i) * S] * g[2];
}

// sigma = lambda tr(G) I + mu (G + G^T): the stress of the displacement gradient G (row-major).
BINBCSR_PHYS_HD void linear_stress(const double G[9], double lambda, double mu, double sigma[9])
{
  const double tr = G[0] + G[4] + G[8];
  BINBCSR_PHYS_UNROLL
  for (int i = 0; i < 3; ++i) BINBCSR_PHYS_UNROLL
  for (int j = 0; j < 3; ++j)
    sigma[3 * i + j] = mu * (G[3 * i + j] + G[3 * j + i]) + (i == j ? lambda * tr : 0.0);
}

// ---- P1 -------------------------------------------------------------------------------------------

// One linear tetrahedron (corotational_assembly.cpp's scalar P1 kernel, same formulas): with r = R g,
//   blocks (a <= b): c_K V (lambda r_a r_b^T + mu r_b r_a^T + mu (g_a . g_b) I) + [a = b] c_M m I
//   rhs_a = -V R sigma g_a - a_M m v_a,   sigma = stress of G = sum_b z_b g_b^T,   m = rho V / 4.
// x, v, X: 12 entries; rhs: 12; blocks: 10 x 9 (written only when Blocks).
template <int S, bool Blocks, bool MassDamping>
BINBCSR_PHYS_HD void p1_element(const double *x, const double *v, const double *X, const double *Dinv,
                                const double *R, double vol, const ElementConstants &k, double *rhs,
                                double *blocks)
{
  double g[4][3], z[4][3];
  barycentric_gradients<S>(Dinv, g);
  rest_frame_displacements<S, 4>(x, v, X, R, k, z);
  double G[9];
  BINBCSR_PHYS_UNROLL
  for (int i = 0; i < 3; ++i) BINBCSR_PHYS_UNROLL
  for (int j = 0; j < 3; ++j)
    G[3 * i + j] = z[0][i] * g[0][j] + z[1][i] * g[1][j] + z[2][i] * g[2][j] + z[3][i] * g[3][j];
  double sigma[9];
  linear_stress(G, k.lambda, k.mu, sigma);
  const double m = k.density * vol * 0.25; // lumped: reference_mass = I / 4
  BINBCSR_PHYS_UNROLL
  for (int a = 0; a < 4; ++a) {
    double sg[3];
    BINBCSR_PHYS_UNROLL
    for (int i = 0; i < 3; ++i)
      sg[i] = sigma[3 * i] * g[a][0] + sigma[3 * i + 1] * g[a][1] + sigma[3 * i + 2] * g[a][2];
    double f[3];
    rotate<S>(R, sg, f);
    BINBCSR_PHYS_UNROLL
    for (int d = 0; d < 3; ++d)
      rhs[(3 * a + d) * S] = -vol * f[d] - (MassDamping ? k.mass_rhs * m * v[(3 * a + d) * S] : 0.0);
  }
  if (!Blocks) return;
  double rg[4][3];
  BINBCSR_PHYS_UNROLL
  for (int a = 0; a < 4; ++a) rotate<S>(R, g[a], rg[a]);
  const double kv = k.stiffness_matrix * vol, kl = kv * k.lambda, km = kv * k.mu;
  int          p = 0;
  BINBCSR_PHYS_UNROLL
  for (int a = 0; a < 4; ++a) BINBCSR_PHYS_UNROLL
  for (int b = a; b < 4; ++b, ++p) {
    const double diag =
      km * (g[a][0] * g[b][0] + g[a][1] * g[b][1] + g[a][2] * g[b][2]) + (a == b ? k.mass_matrix * m : 0.0);
    BINBCSR_PHYS_UNROLL
    for (int i = 0; i < 3; ++i) BINBCSR_PHYS_UNROLL
    for (int j = 0; j < 3; ++j)
      blocks[(9 * p + 3 * i + j) * S] =
        kl * rg[a][i] * rg[b][j] + km * rg[b][i] * rg[a][j] + (i == j ? diag : 0.0);
  }
}

// ---- the state's energy (the run guard's figures) -----------------------------------------------

// What fem_model.cpp's fem_energy (the definition) sums per element, and whether the corner
// tetrahedron is inverted, computed in the element pass from what it has gathered, so that a step
// does not walk the elements (and read 43 MB of K0 for linear_38k) a second time for its health check.

// 1 where the corner tetrahedron's signed volume is not > 0 (element_signed_volume's expression, in
// its order, so that without FMA contraction the test is the same to the bit), else 0.
template <int S> BINBCSR_PHYS_HD double corner_inverted(const double *x)
{
  double d[3][3];
  BINBCSR_PHYS_UNROLL
  for (int k = 0; k < 3; ++k) BINBCSR_PHYS_UNROLL
  for (int c = 0; c < 3; ++c) d[k][c] = x[(3 * (k + 1) + c) * S] - x[c * S];
  const double det = d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1]) -
                     d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0]) +
                     d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]);
  return det > 0 ? 0.0 : 1.0;
}

// u_b = R^T x_b - X_b for n nodes: the displacement in the element's rest frame.
template <int S, int N>
BINBCSR_PHYS_HD void rest_frame_displacement(const double *x, const double *X, const double *R,
                                             double u[N][3])
{
  BINBCSR_PHYS_UNROLL
  for (int b = 0; b < N; ++b) BINBCSR_PHYS_UNROLL
  for (int i = 0; i < 3; ++i)
    u[b][i] = R[(3 * i) * S] * x[(3 * b) * S] + R[(3 * i + 1) * S] * x[(3 * b + 1) * S] +
              R[(3 * i + 2) * S] * x[(3 * b + 2) * S] - X[(3 * b + i) * S];
}

// lambda tr(A) tr(B) + 2 mu sym(A) : sym(B) = sigma(A) : B for displacement gradients A, B (row-major).
BINBCSR_PHYS_HD double strain_product(const double A[9], const double B[9], double lambda, double mu)
{
  double s = 0;
  BINBCSR_PHYS_UNROLL
  for (int i = 0; i < 3; ++i) BINBCSR_PHYS_UNROLL
  for (int j = 0; j < 3; ++j) s += (A[3 * i + j] + A[3 * j + i]) * (B[3 * i + j] + B[3 * j + i]);
  const double ta = A[0] + A[4] + A[8], tb = B[0] + B[4] + B[8];
  return lambda * ta * tb + 0.5 * mu * s;
}

// The elastic energy u^T K0 u / 2 of a linear tetrahedron: V sigma(G) : G / 2 with the constant
// displacement gradient G = sum_b u_b g_b^T, u_b = R^T x_b - X_b, which is R^T F - I (sum_b x_b g_b^T
// = Ds Dm^-1 = F, sum_b X_b g_b^T = Dm Dm^-1 = I): no stored K0 and no nodal vectors read.
template <int S>
BINBCSR_PHYS_HD double p1_elastic_energy(const double *F, const double *R, double vol, double lambda,
                                         double mu)
{
  double G[9];
  BINBCSR_PHYS_UNROLL
  for (int i = 0; i < 3; ++i) BINBCSR_PHYS_UNROLL
  for (int j = 0; j < 3; ++j) // (R^T F)_ij = sum_k R_ki F_kj, column-major
    G[3 * i + j] = R[(3 * i) * S] * F[(3 * j) * S] + R[(3 * i + 1) * S] * F[(3 * j + 1) * S] +
                   R[(3 * i + 2) * S] * F[(3 * j + 2) * S] - (i == j ? 1.0 : 0.0);
  return 0.5 * vol * strain_product(G, G, lambda, mu);
}

// v^T M_e v / 2 = rho V sum_ab Mref_ab v_a . v_b / 2 (Mref: N x N, row-major, symmetric): each pair
// a < b once, doubled (P2: 55 dot products instead of 100).
template <int S, int N>
BINBCSR_PHYS_HD double kinetic_energy(const double *v, const double *Mref, double vol, double density)
{
  double s = 0;
  BINBCSR_PHYS_UNROLL
  for (int a = 0; a < N; ++a) BINBCSR_PHYS_UNROLL
  for (int b = a; b < N; ++b)
    s += (b == a ? 1.0 : 2.0) * Mref[N * a + b] *
         (v[(3 * a) * S] * v[(3 * b) * S] + v[(3 * a + 1) * S] * v[(3 * b + 1) * S] +
          v[(3 * a + 2) * S] * v[(3 * b + 2) * S]);
  return 0.5 * density * vol * s;
}

// The same for a diagonal Mref (lumped mass): sum_a Mref_aa |v_a|^2 only.
template <int S, int N>
BINBCSR_PHYS_HD double kinetic_energy_lumped(const double *v, const double *Mref, double vol, double density)
{
  double s = 0;
  BINBCSR_PHYS_UNROLL
  for (int a = 0; a < N; ++a)
    s += Mref[N * a + a] * (v[(3 * a) * S] * v[(3 * a) * S] + v[(3 * a + 1) * S] * v[(3 * a + 1) * S] +
                            v[(3 * a + 2) * S] * v[(3 * a + 2) * S]);
  return 0.5 * density * vol * s;
}

} // namespace BINBCSR_ELEMENT_SET
} // namespace kernels
} // namespace physics

#include "physics/element_kernels_p2.hpp"
