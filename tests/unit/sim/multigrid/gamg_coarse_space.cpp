// GAMGRefitCoarseSpace (src/sim/gamg_coarse_space.h): refitted to the coordinates PCGAMG was set up with,
// the prolongators are GAMG's own again (up to signs, and the completion of rank-deficient aggregates);
// refitted to a turned and moved body, every prolongator has
// orthonormal columns and the turned body's rigid body modes lie in the finest one's range; a
// hierarchy it cannot refit (smoothed aggregation) is left as it was.
#include <catch2/catch.hpp>
#include <petscksp.h>

#include "sim/gamg_coarse_space.h"
#include "sim/stencil.h"

#include <cmath>
#include <vector>

namespace {

struct Hierarchy {
  Mat                    A   = nullptr;
  KSP                    ksp = nullptr;
  std::vector<PetscReal> coords; // x, y, z per node of the grid
  std::vector<Mat>       interp; // PCMG's prolongators (GAMG's own: no copies here)
  ~Hierarchy()
  {
    KSPDestroy(&ksp);
    MatDestroy(&A);
  }
};

// GAMG (plain aggregation unless nsmooths) set up on the 27-point block stencil of an n^3 node grid,
// with the grid's coordinates.
PetscErrorCode SetUpGAMG(PetscInt n, PetscInt nsmooths, Hierarchy *h, MPI_Comm comm = PETSC_COMM_SELF)
{
  StencilGrid grid;
  PC          pc;
  PetscInt    nlev;

  PetscFunctionBegin;
  grid.nx = grid.ny = grid.nz = n;
  PetscCall(CreateStencilMatrix(comm, grid, MATAIJ, nullptr, &h->A));
  PetscInt r0, r1; // this rank's nodes: rows r0 / 3 .. r1 / 3 (node i + n (j + n k) at (i, j, k))
  PetscCall(MatGetOwnershipRange(h->A, &r0, &r1));
  for (PetscInt node = r0 / 3; node < r1 / 3; ++node)
    h->coords.insert(h->coords.end(), {0.1 * (node % n), 0.1 * (node / n % n), 0.1 * (node / (n * n))});
  PetscCall(KSPCreate(comm, &h->ksp));
  PetscCall(KSPSetOperators(h->ksp, h->A, h->A));
  PetscCall(KSPSetType(h->ksp, KSPCG));
  PetscCall(KSPGetPC(h->ksp, &pc));
  PetscCall(PCSetType(pc, PCGAMG));
  PetscCall(PCGAMGSetNSmooths(pc, nsmooths));
  PetscCall(PCGAMGSetCoarseEqLim(pc, 50));
  PetscCall(PCSetCoordinates(pc, 3, (PetscInt)h->coords.size() / 3, h->coords.data()));
  PetscCall(KSPSetUp(h->ksp));
  PetscCall(PCMGGetLevels(pc, &nlev));
  h->interp.assign(nlev, nullptr);
  for (PetscInt l = 1; l < nlev; ++l) PetscCall(PCMGGetInterpolation(pc, l, &h->interp[l]));
  PetscFunctionReturn(0);
}

std::vector<PetscScalar> Values(Mat P)
{
  const PetscScalar *a;
  PetscInt           m, n, nz;
  PetscBool          done;
  const PetscInt    *ia, *ja;
  REQUIRE(MatGetRowIJ(P, 0, PETSC_FALSE, PETSC_FALSE, &m, &ia, &ja, &done) == 0);
  nz = ia[m];
  REQUIRE(MatRestoreRowIJ(P, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done) == 0);
  REQUIRE(MatSeqAIJGetArrayRead(P, &a) == 0);
  std::vector<PetscScalar> v(a, a + nz);
  REQUIRE(MatSeqAIJRestoreArrayRead(P, &a) == 0);
  return v;
}

// max |P^T P - I| over P's columns that are not zero (an aggregate of fewer than two nodes keeps
// columns beyond its rank as zeros or dependent ones: left out by comparing only full-rank blocks).
double OrthonormalityError(Mat P)
{
  Mat PtP;
  REQUIRE(MatTransposeMatMult(P, P, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &PtP) == 0);
  PetscInt r0, r1;
  REQUIRE(MatGetOwnershipRange(PtP, &r0, &r1) == 0);
  double worst = 0;
  for (PetscInt r = r0; r < r1; ++r) {
    PetscInt           ncols;
    const PetscInt    *cols;
    const PetscScalar *vals;
    REQUIRE(MatGetRow(PtP, r, &ncols, &cols, &vals) == 0);
    double diag = 0;
    for (PetscInt k = 0; k < ncols; ++k)
      if (cols[k] == r) diag = PetscRealPart(vals[k]);
    if (diag > 0.5) // a full-rank column
      for (PetscInt k = 0; k < ncols; ++k)
        worst = std::max(worst, std::fabs(PetscRealPart(vals[k]) - (cols[k] == r ? 1.0 : 0.0)));
    REQUIRE(MatRestoreRow(PtP, r, &ncols, &cols, &vals) == 0);
  }
  REQUIRE(MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPI_DOUBLE, MPI_MAX, PetscObjectComm((PetscObject)PtP)) ==
          0);
  REQUIRE(MatDestroy(&PtP) == 0);
  return worst;
}

} // namespace

TEST_CASE("refitted to its own coordinates, GAMG's plain-aggregation prolongators come back", "[gamg]")
{
  Hierarchy h;
  REQUIRE(SetUpGAMG(8, 0, &h) == 0);
  REQUIRE(h.interp.size() >= 3); // at least two prolongators: the second level's modes are R factors
  std::vector<std::vector<PetscScalar>> before;
  for (size_t l = 1; l < h.interp.size(); ++l) before.push_back(Values(h.interp[l]));
  PetscBool refit;
  REQUIRE(GAMGRefitCoarseSpace(PETSC_COMM_SELF, h.interp, h.coords.data(), (PetscInt)h.coords.size() / 3,
                               &refit) == 0);
  REQUIRE(refit);
  for (size_t l = 1; l < h.interp.size(); ++l) {
    const std::vector<PetscScalar> after = Values(h.interp[l]);
    REQUIRE(after.size() == before[l - 1].size());
    // Q and R up to signs (the aggregate's nodes may be stacked in another order); an aggregate whose
    // modes are rank-deficient (two nodes: no rotation about their axis) completes Q with any unit
    // vector orthogonal to the rest, where GAMG's LAPACK and the refit may choose differently
    size_t differ = 0;
    for (size_t k = 0; k < after.size(); ++k)
      differ +=
        std::fabs(std::fabs(PetscRealPart(after[k])) - std::fabs(PetscRealPart(before[l - 1][k]))) > 1e-10;
    INFO("level " << l << ": " << differ << " of " << after.size() << " entries differ");
    CHECK(differ <= after.size() / 100);
  }
}

namespace {

// The turned-body check on comm (each rank its rows and its nodes' coordinates).
void CheckTurnedBody(MPI_Comm comm)
{
  Hierarchy h;
  REQUIRE(SetUpGAMG(8, 0, &h, comm) == 0);
  // turned 0.7 rad about (1, 2, 2) / 3 and moved
  const double c = std::cos(0.7), s = std::sin(0.7), u[3] = {1 / 3.0, 2 / 3.0, 2 / 3.0};
  double       R[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double cross = (i == j) ? 0 : ((j == (i + 1) % 3) ? -u[(i + 2) % 3] : u[(i + 1) % 3]);
      R[i][j]            = (i == j ? c : 0.0) + (1 - c) * u[i] * u[j] + s * cross;
    }
  std::vector<PetscReal> turned(h.coords.size());
  for (size_t p = 0; p < h.coords.size() / 3; ++p)
    for (int i = 0; i < 3; ++i)
      turned[3 * p + i] = R[i][0] * h.coords[3 * p] + R[i][1] * h.coords[3 * p + 1] +
                          R[i][2] * h.coords[3 * p + 2] + 0.3 * (i + 1);
  PetscBool refit;
  REQUIRE(GAMGRefitCoarseSpace(comm, h.interp, turned.data(), (PetscInt)turned.size() / 3, &refit) == 0);
  REQUIRE(refit);
  for (size_t l = 1; l < h.interp.size(); ++l) {
    INFO("level " << l);
    CHECK(OrthonormalityError(h.interp[l]) < 1e-12);
  }
  // each mode m of the turned body: |m - P P^T m| / |m| ~ 0 on the finest prolongator
  Mat      P = h.interp.back();
  Vec      m, mc, back;
  PetscInt rows;
  REQUIRE(MatGetLocalSize(P, &rows, nullptr) == 0);
  REQUIRE(MatCreateVecs(P, &mc, &m) == 0);
  REQUIRE(VecDuplicate(m, &back) == 0);
  for (int mode = 0; mode < 6; ++mode) {
    PetscScalar *a;
    REQUIRE(VecGetArray(m, &a) == 0);
    for (PetscInt p = 0; p < rows / 3; ++p) {
      const double x = turned[3 * p], y = turned[3 * p + 1], z = turned[3 * p + 2];
      const double v[6][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, -z, y}, {z, 0, -x}, {-y, x, 0}};
      for (int d = 0; d < 3; ++d) a[3 * p + d] = v[mode][d];
    }
    REQUIRE(VecRestoreArray(m, &a) == 0);
    REQUIRE(MatMultTranspose(P, m, mc) == 0);
    REQUIRE(MatMult(P, mc, back) == 0);
    REQUIRE(VecAXPY(back, -1.0, m) == 0);
    PetscReal err, norm;
    REQUIRE(VecNorm(back, NORM_2, &err) == 0);
    REQUIRE(VecNorm(m, NORM_2, &norm) == 0);
    INFO("mode " << mode);
    CHECK(err < 1e-10 * norm);
  }
  REQUIRE(VecDestroy(&m) == 0);
  REQUIRE(VecDestroy(&mc) == 0);
  REQUIRE(VecDestroy(&back) == 0);
}

} // namespace

TEST_CASE("refitted to a turned and moved body, the prolongators span its rigid body modes", "[gamg]")
{
  CheckTurnedBody(PETSC_COMM_SELF);
}

// On several ranks (tests/multigrid.cmake runs it on 2 and 3): aggregates whose nodes lie on two
// ranks are factored by both, on the same gathered modes, and every rank writes its own rows.
TEST_CASE("refitted on every rank's rows, the prolongators span the turned body's modes", "[gamg][mpi]")
{
  CheckTurnedBody(PETSC_COMM_WORLD);
}

TEST_CASE("a smoothed-aggregation hierarchy is not refitted and keeps its prolongators", "[gamg]")
{
  Hierarchy h;
  REQUIRE(SetUpGAMG(8, 1, &h) == 0);
  REQUIRE(h.interp.size() >= 2);
  const std::vector<PetscScalar> before = Values(h.interp.back());
  PetscBool                      refit  = PETSC_TRUE;
  REQUIRE(GAMGRefitCoarseSpace(PETSC_COMM_SELF, h.interp, h.coords.data(), (PetscInt)h.coords.size() / 3,
                               &refit) == 0);
  CHECK(!refit);
  CHECK(Values(h.interp.back()) == before);
}

TEST_CASE("coordinates of another node count, or not finite, are not refitted", "[gamg]")
{
  Hierarchy h;
  REQUIRE(SetUpGAMG(6, 0, &h) == 0);
  const std::vector<PetscScalar> before = Values(h.interp.back());
  PetscBool                      refit  = PETSC_TRUE;
  REQUIRE(GAMGRefitCoarseSpace(PETSC_COMM_SELF, h.interp, h.coords.data(), (PetscInt)h.coords.size() / 3 - 1,
                               &refit) == 0);
  CHECK(!refit);
  h.coords[7] = NAN;
  refit       = PETSC_TRUE;
  REQUIRE(GAMGRefitCoarseSpace(PETSC_COMM_SELF, h.interp, h.coords.data(), (PetscInt)h.coords.size() / 3,
                               &refit) == 0);
  CHECK(!refit);
  CHECK(Values(h.interp.back()) == before);
}
