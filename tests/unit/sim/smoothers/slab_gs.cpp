// Slab Gauss-Seidel (src/sim/slab_gs.h): a sweep is the sequential block Gauss-Seidel sweep in the
// order (step, lane), for row-major and column-major (transposed) sources; the AVX-512 sweep agrees
// with the portable one; the PC and residual applications follow every change of their vectors (they
// keep lane copies of b and x between calls); couplings a slab or more away and singular diagonal blocks are refused.
#include <catch2/catch.hpp>
#include <petscksp.h>

#include "sim/slab_gs.h"

#include <cmath>
#include <random>
#include <vector>

namespace {

// A block-banded SPD test matrix: n block rows, row r coupled to r +- 1 .. r +- reach, blocks random
// (the off-diagonal ones exactly representable in single precision, so that the smoother's storage
// does not round them), the diagonal blocks dominant.
struct Banded {
  int                              n;
  std::vector<SlabGS::Entry>       entries; // one per block (row-major source), diagonal listed twice
  std::vector<double>              blocks;  // 9 per source block, row-major
  std::vector<std::vector<double>> dense;   // 3n x 3n
};

Banded make_banded(int n, int reach, unsigned seed)
{
  Banded       m{n, {}, {}, std::vector<std::vector<double>>(3 * n, std::vector<double>(3 * n, 0.0))};
  std::mt19937 gen(seed);
  std::uniform_int_distribution<int> q(-64, 64);
  const auto                         add = [&](int r, int c, const double *b) {
    m.entries.push_back({r, c, (long)m.blocks.size() / 9, false});
    m.blocks.insert(m.blocks.end(), b, b + 9);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m.dense[3 * r + i][3 * c + j] += b[3 * i + j];
  };
  for (int r = 0; r < n; ++r)
    for (int c = r + 1; c <= r + reach && c < n; ++c) {
      double b[9], bt[9];
      for (int e = 0; e < 9; ++e) b[e] = q(gen) / 64.0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) bt[3 * j + i] = b[3 * i + j];
      add(r, c, b);
      add(c, r, bt);
    }
  for (int r = 0; r < n; ++r) {
    // two halves of the diagonal block (the smoother sums repeated diagonal entries)
    double half[9] = {};
    for (int i = 0; i < 3; ++i) half[4 * i] = 0.5 * (6.0 * reach + 1.0) + 0.1 * i;
    half[1] = half[3] = 0.25;
    add(r, r, half);
    add(r, r, half);
  }
  return m;
}

// The sequential block Gauss-Seidel sweep over the rows in the given order, on the dense matrix.
void reference_sweep(const Banded &m, const std::vector<int> &order, const std::vector<double> &b,
                     std::vector<double> &x)
{
  for (int r : order) {
    double res[3], d[9];
    for (int i = 0; i < 3; ++i) {
      res[i] = b[3 * r + i];
      for (int c = 0; c < 3 * m.n; ++c)
        if (c / 3 != r) res[i] -= m.dense[3 * r + i][c] * x[c];
      for (int j = 0; j < 3; ++j) d[3 * i + j] = m.dense[3 * r + i][3 * r + j];
    }
    // solve d y = res by Cramer's rule
    const double det = d[0] * (d[4] * d[8] - d[5] * d[7]) - d[1] * (d[3] * d[8] - d[5] * d[6]) +
                       d[2] * (d[3] * d[7] - d[4] * d[6]);
    for (int k = 0; k < 3; ++k) {
      double dk[9];
      for (int e = 0; e < 9; ++e) dk[e] = e % 3 == k ? res[e / 3] : d[e];
      x[3 * r + k] = (dk[0] * (dk[4] * dk[8] - dk[5] * dk[7]) - dk[1] * (dk[3] * dk[8] - dk[5] * dk[6]) +
                      dk[2] * (dk[3] * dk[7] - dk[4] * dk[6])) /
                     det;
    }
  }
}

std::vector<int> slab_order(int n, bool forward)
{
  const int        S = (n + SlabGS::lanes - 1) / SlabGS::lanes;
  std::vector<int> order;
  for (int q = 0; q < S; ++q) {
    const int j = forward ? q : S - 1 - q;
    for (int l = 0; l < SlabGS::lanes; ++l)
      if (l * S + j < n) order.push_back(l * S + j);
  }
  return order;
}

} // namespace

TEST_CASE("slab Gauss-Seidel sweeps are the sequential sweeps in slab order", "[slab_gs]")
{
  for (int n : {8, 45, 203}) { // whole slabs, a short last slab, a longer grid
    const int    reach = n < 16 ? 0 : 2;
    const Banded m     = make_banded(n, reach, 7u + n);
    SlabGS       gs;
    REQUIRE(SlabGSBuild(n, m.entries, false, &gs).empty());
    REQUIRE(SlabGSRefill(&gs, m.blocks.data()) == 0);
    std::vector<double> b(3 * n), x0(3 * n);
    for (int i = 0; i < 3 * n; ++i) b[i] = std::sin(0.37 * i), x0[i] = std::cos(0.11 * i);
    for (bool forward : {true, false}) {
      std::vector<double> ref = x0, x = x0, best = x0;
      reference_sweep(m, slab_order(n, forward), b, ref);
      SlabGSSweep(gs, b.data(), x.data(), forward);
      SlabGSSweepBest(gs, b.data(), best.data(), forward);
      for (int i = 0; i < 3 * n; ++i) {
        INFO("n " << n << " forward " << forward << " entry " << i);
        CHECK(x[i] == Approx(ref[i]).epsilon(1e-12).margin(1e-13));
        CHECK(best[i] == Approx(x[i]).epsilon(1e-13).margin(1e-14));
      }
    }
  }
}

TEST_CASE("slab Gauss-Seidel residuals are b - A x", "[slab_gs]")
{
  for (int n : {45, 203}) {
    const Banded m = make_banded(n, 2, 11u + n);
    SlabGS       gs;
    REQUIRE(SlabGSBuild(n, m.entries, false, &gs).empty());
    REQUIRE(SlabGSRefill(&gs, m.blocks.data()) == 0);
    std::vector<double> b(3 * n), x(3 * n), r(3 * n), rbest(3 * n);
    for (int i = 0; i < 3 * n; ++i) b[i] = std::sin(0.21 * i), x[i] = std::cos(0.53 * i);
    SlabGSResidual(gs, b.data(), x.data(), r.data(), false);
    SlabGSResidual(gs, b.data(), x.data(), rbest.data(), true);
    for (int i = 0; i < 3 * n; ++i) {
      double ref = b[i];
      for (int c = 0; c < 3 * n; ++c) ref -= m.dense[i][c] * x[c];
      INFO("n " << n << " entry " << i);
      CHECK(r[i] == Approx(ref).epsilon(1e-12).margin(1e-12));
      CHECK(rbest[i] == Approx(r[i]).epsilon(1e-13).margin(1e-13));
    }
  }
}

TEST_CASE("slab Gauss-Seidel reads column-major transposed sources", "[slab_gs]")
{
  const int    n = 40;
  const Banded m = make_banded(n, 2, 3u);
  // the same matrix as column-major blocks listed at their transposed places
  std::vector<SlabGS::Entry> transposed;
  for (const SlabGS::Entry &e : m.entries) transposed.push_back({e.col, e.row, e.source, true});
  SlabGS a, t;
  REQUIRE(SlabGSBuild(n, m.entries, false, &a).empty());
  REQUIRE(SlabGSBuild(n, transposed, true, &t).empty());
  REQUIRE(SlabGSRefill(&a, m.blocks.data()) == 0);
  std::vector<double> colmajor(m.blocks.size()); // every block stored column by column (SeqBAIJ)
  for (size_t k = 0; k < m.blocks.size() / 9; ++k)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) colmajor[9 * k + 3 * j + i] = m.blocks[9 * k + 3 * i + j];
  REQUIRE(SlabGSRefill(&t, colmajor.data()) == 0);
  std::vector<double> b(3 * n, 1.0), xa(3 * n, 0.0), xt(3 * n, 0.0);
  SlabGSSweep(a, b.data(), xa.data(), true);
  SlabGSSweep(t, b.data(), xt.data(), true);
  // t holds the transpose of the matrix of a; the matrix is symmetric, so the sweeps agree
  for (int i = 0; i < 3 * n; ++i) CHECK(xt[i] == Approx(xa[i]).epsilon(1e-12));
}

TEST_CASE("slab Gauss-Seidel refuses what it cannot sweep", "[slab_gs]")
{
  SECTION("a coupling a slab or more away")
  {
    const Banded      m = make_banded(16, 2, 1u); // slabs of 2 rows: r, r + 2 are coupled
    SlabGS            gs;
    const std::string why = SlabGSBuild(16, m.entries, false, &gs);
    CHECK(why.find("a slab or more away") != std::string::npos);
  }
  SECTION("an entry outside the level")
  {
    SlabGS gs;
    CHECK(!SlabGSBuild(4, {{0, 7, 0, false}}, false, &gs).empty());
  }
  // the refill's error for a 24-row matrix whose diagonal block of row `row` is spoiled by `spoil`
  const auto refill_error = [](int row, void (*spoil)(double *)) {
    Banded m = make_banded(24, 1, 5u);
    for (size_t k = 0; k < m.entries.size(); ++k)
      if (m.entries[k].row == row && m.entries[k].col == row) spoil(&m.blocks[9 * m.entries[k].source]);
    SlabGS gs;
    REQUIRE(SlabGSBuild(24, m.entries, false, &gs).empty());
    PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
    const PetscErrorCode ierr = SlabGSRefill(&gs, m.blocks.data());
    PetscPopErrorHandler();
    return ierr;
  };
  SECTION("a singular diagonal block names its row")
  {
    CHECK(refill_error(13, [](double *b) {
            for (int e = 0; e < 9; ++e) b[e] = 0.0;
          }) == PETSC_ERR_MAT_LU_ZRPVT);
  }
  SECTION("a NaN in a diagonal block is refused the same way")
  {
    CHECK(refill_error(5, [](double *b) { b[4] = NAN; }) == PETSC_ERR_MAT_LU_ZRPVT);
  }
}

TEST_CASE("slab Gauss-Seidel as a PC and a residual follows its vectors", "[slab_gs]")
{
  // A V-cycle's level: pre-smoothing, the residual of what it left, x changed (the coarse correction),
  // post-smoothing with the same b; the lane copies kept between the calls must follow every change
  const int    n = 45;
  const Banded m = make_banded(n, 2, 17u);
  SlabGS       gs;
  REQUIRE(SlabGSBuild(n, m.entries, false, &gs).empty());
  REQUIRE(SlabGSRefill(&gs, m.blocks.data()) == 0);
  Mat A; // any operator: the residual takes the attached layout
  PC  pc;
  Vec b, x, r, w;
  REQUIRE(MatCreateSeqDense(PETSC_COMM_SELF, 3 * n, 3 * n, nullptr, &A) == 0);
  REQUIRE(SlabGSAttach(A, &gs) == 0);
  REQUIRE(PCCreate(PETSC_COMM_SELF, &pc) == 0);
  REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
  REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
  REQUIRE(PCSetOperators(pc, A, A) == 0);
  REQUIRE(SlabGSSetPC(pc, &gs, PETSC_TRUE) == 0);
  REQUIRE(VecCreateSeq(PETSC_COMM_SELF, 3 * n, &b) == 0);
  REQUIRE(VecDuplicate(b, &x) == 0);
  REQUIRE(VecDuplicate(b, &r) == 0);
  REQUIRE(VecDuplicate(b, &w) == 0);
  std::vector<double> bv(3 * n), xv(3 * n, 0.0);
  for (int i = 0; i < 3 * n; ++i) bv[i] = std::sin(0.29 * i);
  PetscScalar *a;
  REQUIRE(VecGetArray(b, &a) == 0);
  for (int i = 0; i < 3 * n; ++i) a[i] = bv[i];
  REQUIRE(VecRestoreArray(b, &a) == 0);
  const auto check_x = [&](const char *when) {
    const PetscScalar *xa;
    REQUIRE(VecGetArrayRead(x, &xa) == 0);
    for (int i = 0; i < 3 * n; ++i) {
      INFO(when << ", entry " << i);
      CHECK(xa[i] == Approx(xv[i]).epsilon(1e-12).margin(1e-13));
    }
    REQUIRE(VecRestoreArrayRead(x, &xa) == 0);
  };
  const auto check_residual = [&](const char *when) {
    REQUIRE(SlabGSResidualMat(A, b, x, r) == 0);
    const PetscScalar *ra;
    REQUIRE(VecGetArrayRead(r, &ra) == 0);
    for (int i = 0; i < 3 * n; ++i) {
      double ref = bv[i];
      for (int c = 0; c < 3 * n; ++c) ref -= m.dense[i][c] * xv[c];
      INFO(when << ", entry " << i);
      CHECK(ra[i] == Approx(ref).epsilon(1e-12).margin(1e-12));
    }
    REQUIRE(VecRestoreArrayRead(r, &ra) == 0);
  };
  const auto smooth = [&](PetscBool zero_guess) {
    PetscInt                    its;
    PCRichardsonConvergedReason reason;
    REQUIRE(PCApplyRichardson(pc, b, x, w, 0, 0, 0, 1, zero_guess, &its, &reason) == 0);
    if (zero_guess) std::fill(xv.begin(), xv.end(), 0.0);
    reference_sweep(m, slab_order(n, true), bv, xv);
    reference_sweep(m, slab_order(n, false), bv, xv);
  };
  smooth(PETSC_TRUE);
  check_x("pre-smoothing from zero");
  check_residual("the residual after it");
  REQUIRE(VecScale(x, 0.5) == 0); // x changed in place
  for (double &v : xv) v *= 0.5;
  check_residual("the residual of x changed in place");
  smooth(PETSC_FALSE);
  check_x("post-smoothing from the changed x");
  REQUIRE(VecGetArray(b, &a) == 0); // b changed in place
  a[7] += 1.0;
  REQUIRE(VecRestoreArray(b, &a) == 0);
  bv[7] += 1.0;
  check_residual("the residual of b changed in place");
  std::vector<double> raw(3 * n, 0.0); // the raw sweep uses the same lane vectors
  SlabGSSweep(gs, bv.data(), raw.data(), true);
  smooth(PETSC_FALSE);
  check_x("smoothing after a raw sweep");
  REQUIRE(VecSet(x, 0.25) == 0);
  std::fill(xv.begin(), xv.end(), 0.25);
  check_residual("the residual after VecSet");
  REQUIRE(VecDestroy(&w) == 0);
  REQUIRE(VecDestroy(&r) == 0);
  REQUIRE(VecDestroy(&x) == 0);
  REQUIRE(VecDestroy(&b) == 0);
  REQUIRE(PCDestroy(&pc) == 0);
  REQUIRE(MatDestroy(&A) == 0);
}

TEST_CASE("slab Gauss-Seidel on a rank's rows: the halo takes the other ranks' part", "[slab_gs][mpi]")
{
  // The banded matrix split into contiguous row ranges, one per rank: each rank's slabs hold its rows'
  // blocks among themselves and, in the halo, those toward other ranks' rows. A sweep from a guess is the
  // sequential sweep of the rank's rows with the other ranks' x fixed (block Jacobi between the ranks);
  // from zero it ignores them; the residual is b - A x of the whole matrix. On one rank: no halo.
  PetscMPIInt rank, size;
  REQUIRE(MPI_Comm_rank(PETSC_COMM_WORLD, &rank) == 0);
  REQUIRE(MPI_Comm_size(PETSC_COMM_WORLD, &size) == 0);
  const int    n = 45 * size, reach = 2, r0 = 45 * rank, nl = 45;
  const Banded m = make_banded(n, reach, 23u);
  // the rank's rows as a level of their own (their blocks among them), and the halo
  Banded local{nl, {}, {}, std::vector<std::vector<double>>(3 * nl, std::vector<double>(3 * nl))};
  std::vector<SlabGS::HaloEntry> halo;
  std::vector<PetscInt>          ghosts;
  for (size_t k = 0; k < m.entries.size(); ++k) {
    const SlabGS::Entry &e = m.entries[k];
    if (e.row < r0 || e.row >= r0 + nl) continue;
    if (e.col >= r0 && e.col < r0 + nl) {
      local.entries.push_back({e.row - r0, e.col - r0, e.source, false});
      continue;
    }
    int g = 0;
    while (g < (int)ghosts.size() && ghosts[g] != e.col) ++g;
    if (g == (int)ghosts.size()) ghosts.push_back(e.col);
    halo.push_back({e.row - r0, g, e.source, false});
  }
  for (int i = 0; i < 3 * nl; ++i)
    for (int j = 0; j < 3 * nl; ++j) local.dense[i][j] = m.dense[3 * r0 + i][3 * r0 + j];
  SlabGS gs;
  REQUIRE(SlabGSBuild(nl, local.entries, false, &gs).empty());
  if (size > 1) SlabGSSetHalo(&gs, halo, ghosts);
  REQUIRE(SlabGSRefill(&gs, m.blocks.data()) == 0);
  CHECK(gs.distributed == (size > 1));
  CHECK(gs.halo.size() == halo.size());

  Mat A; // any operator of the level's layout: the residual takes the attached slabs
  Vec b, x, r;
  REQUIRE(MatCreateDense(PETSC_COMM_WORLD, 3 * nl, 3 * nl, 3 * n, 3 * n, nullptr, &A) == 0);
  REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
  REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
  REQUIRE(SlabGSAttach(A, &gs) == 0);
  REQUIRE(MatCreateVecs(A, &x, &b) == 0);
  REQUIRE(VecDuplicate(b, &r) == 0);
  std::vector<double> bv(3 * n), xv(3 * n);
  for (int i = 0; i < 3 * n; ++i) bv[i] = std::sin(0.31 * i), xv[i] = std::cos(0.17 * i);
  const auto set = [&](Vec v, const std::vector<double> &from) {
    PetscScalar *a;
    REQUIRE(VecGetArray(v, &a) == 0);
    for (int i = 0; i < 3 * nl; ++i) a[i] = from[3 * r0 + i];
    REQUIRE(VecRestoreArray(v, &a) == 0);
  };
  set(b, bv);
  set(x, xv);

  // the residual of the whole matrix
  REQUIRE(SlabGSResidualMat(A, b, x, r) == 0);
  const PetscScalar *ra;
  REQUIRE(VecGetArrayRead(r, &ra) == 0);
  for (int i = 0; i < 3 * nl; ++i) {
    double ref = bv[3 * r0 + i];
    for (int c = 0; c < 3 * n; ++c) ref -= m.dense[3 * r0 + i][c] * xv[c];
    INFO("rank " << rank << " residual entry " << i);
    CHECK(ra[i] == Approx(ref).epsilon(1e-12).margin(1e-12));
  }
  REQUIRE(VecRestoreArrayRead(r, &ra) == 0);

  // a symmetric sweep from the guess: the other ranks' part on the right-hand side
  for (PetscBool zero_guess : {PETSC_FALSE, PETSC_TRUE}) {
    std::vector<double> bl(3 * nl), xl(3 * nl);
    for (int i = 0; i < 3 * nl; ++i) {
      bl[i] = bv[3 * r0 + i];
      xl[i] = zero_guess ? 0.0 : xv[3 * r0 + i];
      if (!zero_guess)
        for (int c = 0; c < 3 * n; ++c)
          if (c / 3 < r0 || c / 3 >= r0 + nl) bl[i] -= m.dense[3 * r0 + i][c] * xv[c];
    }
    reference_sweep(local, slab_order(nl, true), bl, xl);
    reference_sweep(local, slab_order(nl, false), bl, xl);
    set(x, xv);
    REQUIRE(SlabGSApplySweeps(&gs, b, x, 1, zero_guess) == 0);
    const PetscScalar *xa;
    REQUIRE(VecGetArrayRead(x, &xa) == 0);
    for (int i = 0; i < 3 * nl; ++i) {
      INFO("rank " << rank << (zero_guess ? " from zero" : " from the guess") << ", entry " << i);
      CHECK(xa[i] == Approx(xl[i]).epsilon(1e-12).margin(1e-13));
    }
    REQUIRE(VecRestoreArrayRead(x, &xa) == 0);
  }
  gs = SlabGS(); // its halo's scatter before the Vecs it was made for
  REQUIRE(VecDestroy(&r) == 0);
  REQUIRE(VecDestroy(&x) == 0);
  REQUIRE(VecDestroy(&b) == 0);
  REQUIRE(MatDestroy(&A) == 0);
}
