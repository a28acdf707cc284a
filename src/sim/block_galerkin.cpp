#include "sim/block_galerkin.h"
#include <petsc/private/matimpl.h> /* assembled, was_assembled: see BlockGalerkinRefill */

#include <algorithm>

namespace {

PetscLogEvent BG_Refill = 0;

// -log_view event: a refill of the coarse operator (the product's terms summed into its blocks)
PetscErrorCode BlockGalerkinRegisterEvents()
{
  static PetscClassId classid = 0;
  PetscFunctionBegin;
  if (classid) PetscFunctionReturn(0);
  PetscCall(PetscClassIdRegister("BlockGalerkin", &classid));
  PetscCall(PetscLogEventRegister("BlockGalerkinRefill", classid, &BG_Refill));
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode BlockGalerkinCreate(const std::vector<PetscInt> &row, const std::vector<PetscInt> &col,
                                   bool row_major, bool mirrored, bool symmetric,
                                   const std::vector<std::vector<BlockWeight>> &weights, PetscInt n_coarse,
                                   BlockGalerkin *g, const std::vector<char> *mirror_block)
{
  PetscFunctionBegin;
  PetscCheck(row.size() == col.size(), PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "%zu block rows but %zu columns",
             row.size(), col.size());
  PetscCheck(!mirror_block || mirror_block->size() == row.size(), PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "%zu blocks but %zu mirror flags", row.size(), mirror_block ? mirror_block->size() : 0);
  // Terms with the destination as (I, J) first; Ac's block index replaces it once the pattern is known.
  struct Pending {
    PetscInt src, I, J;
    double   w;
  };
  std::vector<Pending>               pending;
  std::vector<std::vector<PetscInt>> cols(n_coarse);
  for (size_t k = 0; k < row.size(); ++k) {
    const PetscInt r = row[k], c = col[k];
    PetscCheck(r >= 0 && r < (PetscInt)weights.size() && c >= 0 && c < (PetscInt)weights.size(),
               PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "block %zu at (%" PetscInt_FMT ", %" PetscInt_FMT ") is outside the %zu nodes", k, r, c,
               weights.size());
    // Ac is column-major (BAIJ): a row-major source block lands transposed in memory, and the mirrored
    // block (the transpose) the other way round.
    for (const BlockWeight &a : weights[r])
      for (const BlockWeight &b : weights[c]) {
        const PetscInt src = (PetscInt)k;
        pending.push_back({row_major ? ~src : src, a.coarse, b.coarse, a.w * b.w});
        cols[a.coarse].push_back(b.coarse);
        if (mirrored && r != c && (!mirror_block || (*mirror_block)[k])) {
          pending.push_back({row_major ? src : ~src, b.coarse, a.coarse, a.w * b.w});
          cols[b.coarse].push_back(a.coarse);
        }
      }
  }
  std::vector<PetscInt> nnz(n_coarse);
  for (PetscInt I = 0; I < n_coarse; ++I) {
    std::sort(cols[I].begin(), cols[I].end());
    cols[I].erase(std::unique(cols[I].begin(), cols[I].end()), cols[I].end());
    nnz[I] = std::max<PetscInt>(1, (PetscInt)cols[I].size());
  }
  PetscCall(MatCreateSeqBAIJ(PETSC_COMM_SELF, 3, 3 * n_coarse, 3 * n_coarse, 0, nnz.data(), &g->Ac));
  PetscCall(MatSetOptionsPrefix(g->Ac, "grid_mg_coarse_")); // -mat_view is for the system matrix
  {
    const PetscScalar zero[9] = {0};
    for (PetscInt I = 0; I < n_coarse; ++I) {
      if (cols[I].empty()) PetscCall(MatSetValuesBlocked(g->Ac, 1, &I, 1, &I, zero, INSERT_VALUES));
      for (PetscInt J : cols[I]) PetscCall(MatSetValuesBlocked(g->Ac, 1, &I, 1, &J, zero, INSERT_VALUES));
    }
  }
  PetscCall(MatAssemblyBegin(g->Ac, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(g->Ac, MAT_FINAL_ASSEMBLY));
  PetscCall(MatSetOption(g->Ac, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_TRUE));
  PetscCall(MatSetOption(g->Ac, MAT_SYMMETRIC, PETSC_TRUE));
  {
    const PetscInt *ia, *ja;
    PetscInt        nr;
    PetscBool       done;
    PetscCall(MatGetRowIJ(g->Ac, 0, PETSC_FALSE, PETSC_TRUE, &nr, &ia, &ja, &done));
    PetscCheck(done && nr == n_coarse, PETSC_COMM_SELF, PETSC_ERR_PLIB,
               "no block structure of the coarse matrix");
    g->terms.clear();
    g->mirror.clear();
    for (const Pending &p : pending) {
      if (symmetric && p.I > p.J) continue; // the transpose of block (J, I)
      const PetscInt *at = std::lower_bound(ja + ia[p.I], ja + ia[p.I + 1], p.J);
      g->terms.push_back({p.src, (PetscInt)(at - ja), p.w});
    }
    if (symmetric) // the pattern is symmetric: it came from the terms, with (J, I) for every (I, J)
      for (PetscInt I = 0; I < nr; ++I)
        for (PetscInt k = ia[I]; k < ia[I + 1] && ja[k] < I; ++k) {
          const PetscInt  J  = ja[k];
          const PetscInt *at = std::lower_bound(ja + ia[J], ja + ia[J + 1], I);
          PetscCheck(at < ja + ia[J + 1] && *at == I, PETSC_COMM_SELF, PETSC_ERR_PLIB,
                     "coarse block (%" PetscInt_FMT ", %" PetscInt_FMT ") has no transpose", I, J);
          g->mirror.push_back({k, (PetscInt)(at - ja)});
        }
    // Grouped by destination, a refill sums each block of Ac in registers and stores it once (the
    // source blocks it reads are a few MB, cache-resident; Ac's are written in order).
    std::stable_sort(
      g->terms.begin(), g->terms.end(),
      [](const BlockGalerkin::Term &x, const BlockGalerkin::Term &y) { return x.dst < y.dst; });
    g->start.assign(ia[nr] + 1, 0);
    for (const BlockGalerkin::Term &t : g->terms) g->start[t.dst + 1]++;
    for (PetscInt b = 0; b < ia[nr]; ++b) g->start[b + 1] += g->start[b];
    PetscCall(MatRestoreRowIJ(g->Ac, 0, PETSC_FALSE, PETSC_TRUE, &nr, &ia, &ja, &done));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode BlockGalerkinBlocksOf(Mat A, std::vector<PetscInt> *row, std::vector<PetscInt> *col)
{
  const PetscInt *ia, *ja;
  PetscInt        nr;
  PetscBool       done;

  PetscFunctionBegin;
  PetscCall(MatGetRowIJ(A, 0, PETSC_FALSE, PETSC_TRUE, &nr, &ia, &ja, &done));
  PetscCheck(done, PETSC_COMM_SELF, PETSC_ERR_SUP, "no block structure of the coarse matrix");
  row->clear(), col->clear();
  for (PetscInt I = 0; I < nr; ++I)
    for (PetscInt k = ia[I]; k < ia[I + 1]; ++k) row->push_back(I), col->push_back(ja[k]);
  PetscCall(MatRestoreRowIJ(A, 0, PETSC_FALSE, PETSC_TRUE, &nr, &ia, &ja, &done));
  PetscFunctionReturn(0);
}

PetscErrorCode BlockGalerkinRefill(BlockGalerkin *g, const PetscScalar *values)
{
  PetscScalar *a;

  PetscFunctionBegin;
  PetscCall(BlockGalerkinRegisterEvents());
  PetscCall(PetscLogEventBegin(BG_Refill, 0, 0, 0, 0));
  PetscCall(MatSeqBAIJGetArray(g->Ac, &a));
  const BlockGalerkin::Term *term = g->terms.data();
  for (size_t b = 0; b + 1 < g->start.size(); ++b) {
    double acc[9] = {0};
    for (PetscInt t = g->start[b]; t < g->start[b + 1]; ++t) {
      const double w = term[t].w;
      if (term[t].src >= 0) {
        const PetscScalar *s = values + 9 * term[t].src;
        for (int k = 0; k < 9; ++k) acc[k] += w * s[k];
      } else {
        const PetscScalar *s = values + 9 * ~term[t].src;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) acc[3 * i + j] += w * s[3 * j + i];
      }
    }
    for (int k = 0; k < 9; ++k) a[9 * b + k] = acc[k];
  }
  for (const auto &m : g->mirror) {
    PetscScalar *lower = a + 9 * m.first, *upper = a + 9 * m.second;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) lower[3 * i + j] = upper[3 * j + i];
  }
  PetscCall(MatSeqBAIJRestoreArray(g->Ac, &a));
  // A new state, so that the level's smoother and factorisation see the new values. Assembled as a
  // first assembly: a re-assembly without new nonzeros returns (PETSc 3.22) before it marks BAIJ's
  // cached inverses of the diagonal blocks stale, and SOR then smoothed with the previous step's
  // inverses (the V-cycle turned indefinite at the third step of the cloth).
  g->Ac->assembled     = PETSC_FALSE;
  g->Ac->was_assembled = PETSC_FALSE;
  PetscCall(MatAssemblyBegin(g->Ac, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(g->Ac, MAT_FINAL_ASSEMBLY));
  PetscCall(PetscLogFlops(18.0 * g->terms.size()));
  PetscCall(PetscLogEventEnd(BG_Refill, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

PetscErrorCode BlockGalerkinDestroy(BlockGalerkin *g)
{
  PetscFunctionBegin;
  PetscCall(MatDestroy(&g->Ac));
  g->terms.clear();
  g->start.clear();
  PetscFunctionReturn(0);
}
