// Block Galerkin products (src/sim/block_galerkin.h): Ac = W^T A W from 3x3 blocks equals the dense product,
// for sources given as whole or mirrored (upper) COO lists, row- or column-major blocks, summed in full or
// as a symmetric product (upper blocks summed, the lower ones their transposes), and a refill with new
// values replaces the old ones.
#include <catch2/catch.hpp>
#include <petscmat.h>

#include "sim/block_galerkin.h"

#include <cmath>
#include <random>
#include <vector>

namespace {

// A symmetric block matrix on nf fine nodes: a random pattern of pairs (with the diagonal), values random.
struct Source {
  int                              nf;
  std::vector<PetscInt>            row, col; // whole list: every off-diagonal pair both ways
  std::vector<double>              values;   // 9 per block, row-major
  std::vector<std::vector<double>> dense;    // 3 nf x 3 nf
};

Source make_source(int nf, unsigned seed)
{
  Source       s{nf, {}, {}, {}, std::vector<std::vector<double>>(3 * nf, std::vector<double>(3 * nf, 0.0))};
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int>     pick(0, 3);
  const auto                             add = [&](int r, int c, const double *b) {
    s.row.push_back(r), s.col.push_back(c);
    s.values.insert(s.values.end(), b, b + 9);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s.dense[3 * r + i][3 * c + j] += b[3 * i + j];
  };
  for (int r = 0; r < nf; ++r) {
    double d[9];
    for (int i = 0; i < 3; ++i)
      for (int j = i; j < 3; ++j) d[3 * i + j] = d[3 * j + i] = u(gen) + (i == j ? 4.0 : 0.0);
    add(r, r, d);
    for (int c = r + 1; c < nf; ++c) {
      if (pick(gen) != 0) continue;
      double b[9], bt[9];
      for (int e = 0; e < 9; ++e) b[e] = u(gen);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) bt[3 * j + i] = b[3 * i + j];
      add(r, c, b);
      add(c, r, bt);
    }
  }
  return s;
}

// Each fine node interpolates from 1 to 3 coarse nodes with random weights; every coarse node is used.
std::vector<std::vector<BlockWeight>> make_weights(int nf, int nc, unsigned seed)
{
  std::mt19937                           gen(seed);
  std::uniform_real_distribution<double> u(0.1, 1.0);
  std::uniform_int_distribution<int>     node(0, nc - 1), count(1, 3);
  std::vector<std::vector<BlockWeight>>  w(nf);
  for (int i = 0; i < nf; ++i) {
    std::vector<int> used;
    if (i < nc) used.push_back(i);
    for (int k = (int)used.size(); k < count(gen); ++k) {
      const int c = node(gen);
      if (std::find(used.begin(), used.end(), c) == used.end()) used.push_back(c);
    }
    for (int c : used) w[i].push_back({c, u(gen)});
  }
  return w;
}

// Ac as a dense matrix from the SeqBAIJ result
std::vector<std::vector<double>> dense_of(Mat Ac, int nc)
{
  std::vector<std::vector<double>> d(3 * nc, std::vector<double>(3 * nc, 0.0));
  for (PetscInt r = 0; r < 3 * nc; ++r) {
    PetscInt           n;
    const PetscInt    *cols;
    const PetscScalar *vals;
    REQUIRE(MatGetRow(Ac, r, &n, &cols, &vals) == 0);
    for (PetscInt k = 0; k < n; ++k) d[r][cols[k]] = vals[k];
    REQUIRE(MatRestoreRow(Ac, r, &n, &cols, &vals) == 0);
  }
  return d;
}

void check_product(const Source &s, const std::vector<std::vector<BlockWeight>> &w, int nc, Mat Ac)
{
  std::vector<std::vector<double>> W(3 * s.nf, std::vector<double>(3 * nc, 0.0));
  for (int i = 0; i < s.nf; ++i)
    for (const BlockWeight &b : w[i])
      for (int k = 0; k < 3; ++k) W[3 * i + k][3 * b.coarse + k] += b.w;
  const std::vector<std::vector<double>> got = dense_of(Ac, nc);
  for (int I = 0; I < 3 * nc; ++I)
    for (int J = 0; J < 3 * nc; ++J) {
      double ref = 0;
      for (int a = 0; a < 3 * s.nf; ++a)
        for (int b = 0; b < 3 * s.nf; ++b) ref += W[a][I] * s.dense[a][b] * W[b][J];
      INFO("entry (" << I << ", " << J << ")");
      CHECK(got[I][J] == Approx(ref).epsilon(1e-12).margin(1e-12));
    }
}

} // namespace

TEST_CASE("block Galerkin products equal W^T A W", "[block_galerkin]")
{
  const int    nf = 23, nc = 7;
  const Source s = make_source(nf, 3u);
  const auto   w = make_weights(nf, nc, 5u);
  for (bool symmetric : {false, true})
    for (bool mirrored : {false, true})
      for (bool row_major : {true, false}) {
        INFO("symmetric " << symmetric << " mirrored " << mirrored << " row-major " << row_major);
        // the list: whole, or each off-diagonal pair once (row < col) standing for both
        std::vector<PetscInt> row, col;
        std::vector<double>   values;
        for (size_t k = 0; k < s.row.size(); ++k) {
          if (mirrored && s.row[k] > s.col[k]) continue;
          row.push_back(s.row[k]), col.push_back(s.col[k]);
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
              values.push_back(row_major ? s.values[9 * k + 3 * i + j] : s.values[9 * k + 3 * j + i]);
        }
        BlockGalerkin g;
        REQUIRE(BlockGalerkinCreate(row, col, row_major, mirrored, symmetric, w, nc, &g) == 0);
        if (symmetric) CHECK(!g.mirror.empty());
        std::vector<double> garbage(values.size(), 7.0); // a first refill the second must replace
        REQUIRE(BlockGalerkinRefill(&g, garbage.data()) == 0);
        REQUIRE(BlockGalerkinRefill(&g, values.data()) == 0);
        check_product(s, w, nc, g.Ac);
        if (symmetric) { // blocks off the diagonal: exact transposes, not only to rounding
          const auto d = dense_of(g.Ac, nc);
          for (int I = 0; I < 3 * nc; ++I)
            for (int J = 0; J < I; ++J)
              if (I / 3 != J / 3) CHECK(d[I][J] == d[J][I]);
        }
        REQUIRE(BlockGalerkinDestroy(&g) == 0);
      }
}

TEST_CASE("block Galerkin products refuse blocks outside the fine nodes", "[block_galerkin]")
{
  BlockGalerkin                               g;
  const std::vector<std::vector<BlockWeight>> w(2, std::vector<BlockWeight>{{0, 1.0}});
  PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
  const PetscErrorCode ierr = BlockGalerkinCreate({0, 1}, {0, 5}, true, false, true, w, 1, &g);
  PetscPopErrorHandler();
  CHECK(ierr == PETSC_ERR_ARG_OUTOFRANGE);
  REQUIRE(BlockGalerkinDestroy(&g) == 0);
}
