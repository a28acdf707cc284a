/* MATMPIBINBCSR assembly: MatSetValues (own rows to the parts, other ranks' rows to the stash),
   the stash exchange at assembly, the compression of the off-diagonal part at the first final
   assembly, and COO assembly with entries owned by other ranks. */
#include "mpibinbcsr.h"

#include <algorithm>
#include <type_traits>

/* Sets the entries of one owned row; cols are global; vals NULL: zeros (PETSc's MatSetValues takes a
   NULL array as zeros; DMDA's preallocation inserts its pattern that way). */
static PetscErrorCode SetOwnedRow(Mat mat, PetscInt lrow, PetscInt n, const PetscInt cols[],
                                  const PetscScalar vals[], PetscInt vstride, InsertMode mode)
{
  Mat_MPIBinBCSR                       *b      = MPIBinBCSR(mat);
  const PetscInt                        cstart = mat->cmap->rstart, cend = mat->cmap->rend, N = mat->cmap->N;
  thread_local std::vector<PetscInt>    acol, bcol;
  thread_local std::vector<PetscScalar> aval, bval;

  PetscFunctionBegin;
  acol.clear();
  aval.clear();
  bcol.clear();
  bval.clear();
  for (PetscInt j = 0; j < n; j++) {
    const PetscInt    c = cols[j];
    const PetscScalar v = vals ? vals[j * vstride] : 0.0;
    if (c < 0) continue;
    PetscCheck(c < N, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "Column %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", c, N);
    if (c >= cstart && c < cend) {
      acol.push_back(c - cstart);
      aval.push_back(v);
    } else if (!b->compressed) {
      const long long key = static_cast<long long>(lrow) * N + c;
      if (mode == ADD_VALUES) b->b_staging[key] += v;
      else b->b_staging[key] = v;
    } else {
      PetscInt lc;
      PetscCall(MatMPIBinBCSRGhostIndex(mat, c, &lc));
      if (lc < 0) {
        if (b->ignore_new_offdiag) continue;
        SETERRQ(PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
                "New nonzero at (%" PetscInt_FMT ",%" PetscInt_FMT
                ") in the off-diagonal part after the pattern was fixed by the first final assembly",
                lrow + mat->rmap->rstart, c);
      }
      bcol.push_back(lc);
      bval.push_back(v);
    }
  }
  if (!acol.empty())
    PetscCall(
      MatSetValues(b->A, 1, &lrow, static_cast<PetscInt>(acol.size()), acol.data(), aval.data(), mode));
  if (!bcol.empty())
    PetscCall(
      MatSetValues(b->B, 1, &lrow, static_cast<PetscInt>(bcol.size()), bcol.data(), bval.data(), mode));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatSetValues_MPIBinBCSR(Mat mat, PetscInt m, const PetscInt idxm[], PetscInt n,
                                                    const PetscInt idxn[], const PetscScalar v[],
                                                    InsertMode mode)
{
  Mat_MPIBinBCSR *b      = MPIBinBCSR(mat);
  const PetscInt  rstart = mat->rmap->rstart, rend = mat->rmap->rend;

  PetscFunctionBegin;
  PetscCheck(b->A, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "Call MatSetUp() or a preallocation routine before MatSetValues() on a MATMPIBINBCSR matrix");
  for (PetscInt i = 0; i < m; i++) {
    const PetscInt row = idxm[i];
    if (row < 0) continue;
    PetscCheck(row < mat->rmap->N, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "Row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", row, mat->rmap->N);
    const PetscScalar *vrow    = !v ? nullptr : b->roworiented ? v + i * n : v + i;
    const PetscInt     vstride = b->roworiented ? 1 : m;
    if (row >= rstart && row < rend) {
      PetscCall(SetOwnedRow(mat, row - rstart, n, idxn, vrow, vstride, mode));
    } else if (!b->donotstash) {
      PetscCheck(!mat->nooffprocentries, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG,
                 "Setting off-process row %" PetscInt_FMT " although MAT_NO_OFF_PROC_ENTRIES was set", row);
      for (PetscInt j = 0; j < n; j++) {
        if (idxn[j] < 0) continue;
        b->stash_row.push_back(row);
        b->stash_col.push_back(idxn[j]);
        b->stash_val.push_back(vrow ? vrow[j * vstride] : 0.0);
      }
    }
  }
  PetscFunctionReturn(0);
}

/* Sends the stashed entries to the owners of their rows and sets them there. */
static PetscErrorCode ExchangeStash(Mat mat)
{
  Mat_MPIBinBCSR *b    = MPIBinBCSR(mat);
  MPI_Comm        comm = PetscObjectComm((PetscObject)mat);
  int             flags[2], global[2];

  PetscFunctionBegin;
  if (mat->nooffprocentries) PetscFunctionReturn(0);
  flags[0] = static_cast<int>(mat->insertmode);
  flags[1] = b->stash_row.empty() ? 0 : 1;
  PetscCallMPI(MPI_Allreduce(flags, global, 2, MPI_INT, MPI_BOR, comm));
  PetscCheck(global[0] != (ADD_VALUES | INSERT_VALUES), comm, PETSC_ERR_ARG_WRONGSTATE,
             "Some ranks inserted values while others added");
  if (!global[1]) PetscFunctionReturn(0);
  const InsertMode         mode  = static_cast<InsertMode>(global[0]);
  const PetscInt           nsend = static_cast<PetscInt>(b->stash_row.size());
  std::vector<PetscMPIInt> dest(nsend);
  for (PetscInt q = 0; q < nsend; q++) PetscCall(PetscLayoutFindOwner(mat->rmap, b->stash_row[q], &dest[q]));
  PetscSF  sf;
  PetscInt nrecv;
  PetscCall(MatMPIBinBCSRBuildSendSF(comm, nsend, dest.data(), &sf, &nrecv));
  std::vector<PetscInt>    rrow(nrecv), rcol(nrecv);
  std::vector<PetscScalar> rval(nrecv);
  PetscCall(PetscSFReduceBegin(sf, MPIU_INT, b->stash_row.data(), rrow.data(), MPI_REPLACE));
  PetscCall(PetscSFReduceBegin(sf, MPIU_INT, b->stash_col.data(), rcol.data(), MPI_REPLACE));
  PetscCall(PetscSFReduceBegin(sf, MPIU_SCALAR, b->stash_val.data(), rval.data(), MPI_REPLACE));
  PetscCall(PetscSFReduceEnd(sf, MPIU_INT, b->stash_row.data(), rrow.data(), MPI_REPLACE));
  PetscCall(PetscSFReduceEnd(sf, MPIU_INT, b->stash_col.data(), rcol.data(), MPI_REPLACE));
  PetscCall(PetscSFReduceEnd(sf, MPIU_SCALAR, b->stash_val.data(), rval.data(), MPI_REPLACE));
  PetscCall(PetscSFDestroy(&sf));
  b->stash_row.clear();
  b->stash_col.clear();
  b->stash_val.clear();
  for (PetscInt r = 0; r < nrecv; r++)
    PetscCall(SetOwnedRow(mat, rrow[r] - mat->rmap->rstart, 1, &rcol[r], &rval[r], 1, mode));
  PetscFunctionReturn(0);
}

/* First final assembly: garray from the staged off-diagonal entries, B built with exact
   preallocation, the ghost scatter. */
static PetscErrorCode CompressOffDiagonal(Mat mat)
{
  Mat_MPIBinBCSR *b  = MPIBinBCSR(mat);
  const PetscInt  bs = mat->cmap->bs, m = mat->rmap->n, N = mat->cmap->N;

  PetscFunctionBegin;
  std::vector<std::pair<long long, PetscScalar>> entries(b->b_staging.begin(), b->b_staging.end());
  std::sort(entries.begin(), entries.end(), [](const auto &x, const auto &y) { return x.first < y.first; });
  b->garray.clear();
  for (const auto &e : entries) b->garray.push_back(static_cast<PetscInt>(e.first % N) / bs);
  std::sort(b->garray.begin(), b->garray.end());
  b->garray.erase(std::unique(b->garray.begin(), b->garray.end()), b->garray.end());
  const PetscInt ng = static_cast<PetscInt>(b->garray.size());

  std::vector<PetscInt> nnz(m, 0);
  for (const auto &e : entries) nnz[e.first / N]++;
  PetscCall(MatDestroy(&b->B));
  PetscCall(MatMPIBinBCSRCreatePart(mat, m, ng * bs, &b->B));
  PetscCall(MatSeqAIJSetPreallocation(b->B, 0, nnz.data()));
  b->compressed = PETSC_TRUE; /* SetOwnedRow now maps through garray */
  std::vector<PetscInt>    cols;
  std::vector<PetscScalar> vals;
  for (std::size_t k = 0; k < entries.size();) {
    const PetscInt row = static_cast<PetscInt>(entries[k].first / N);
    cols.clear();
    vals.clear();
    for (; k < entries.size() && entries[k].first / N == row; k++) {
      PetscInt lc;
      PetscCall(MatMPIBinBCSRGhostIndex(mat, static_cast<PetscInt>(entries[k].first % N), &lc));
      cols.push_back(lc);
      vals.push_back(entries[k].second);
    }
    PetscCall(MatSetValues(b->B, 1, &row, static_cast<PetscInt>(cols.size()), cols.data(), vals.data(),
                           INSERT_VALUES));
  }
  PetscCall(MatAssemblyBegin(b->B, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->B, MAT_FINAL_ASSEMBLY));
  b->b_staging.clear();
  PetscCall(MatMPIBinBCSRSetUpScatter(mat));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatAssemblyBegin_MPIBinBCSR(Mat mat, MatAssemblyType type)
{
  PetscFunctionBegin;
  (void)mat;
  (void)type; /* the exchange happens in MatAssemblyEnd, where the insert mode of every rank is known */
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatAssemblyEnd_MPIBinBCSR(Mat mat, MatAssemblyType type)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (b->coo_just_assembled) { /* MatSetValuesCOO refilled both parts; nothing is stashed */
    b->coo_just_assembled = PETSC_FALSE;
    if (b->coo->composed) { /* the two-source refill leaves its parts to be assembled here, inside mat's
                               assembly: -mat_view shows mat, not them */
      PetscCall(MatAssemblyBegin(b->A, MAT_FINAL_ASSEMBLY));
      PetscCall(MatAssemblyEnd(b->A, MAT_FINAL_ASSEMBLY));
      PetscCall(MatAssemblyBegin(b->B, MAT_FINAL_ASSEMBLY));
      PetscCall(MatAssemblyEnd(b->B, MAT_FINAL_ASSEMBLY));
    }
    PetscFunctionReturn(0);
  }
  PetscCheck(b->A, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_WRONGSTATE,
             "Call MatSetUp() or a preallocation routine before assembling a MATMPIBINBCSR matrix");
  PetscCall(ExchangeStash(mat));
  PetscCall(MatAssemblyBegin(b->A, type));
  PetscCall(MatAssemblyEnd(b->A, type));
  if (type == MAT_FINAL_ASSEMBLY && !b->compressed) {
    PetscCall(CompressOffDiagonal(mat));
  } else if (b->compressed) {
    PetscCall(MatAssemblyBegin(b->B, type));
    PetscCall(MatAssemblyEnd(b->B, type));
  }
  PetscFunctionReturn(0);
}

/* ---------------------------------------------------------------- COO ------------------------- */

PETSC_INTERN PetscErrorCode MatMPIBinBCSRDestroyCoo(Mat mat)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (b->coo) {
    PetscCall(PetscSFDestroy(&b->coo->sf));
    delete b->coo;
    b->coo = nullptr;
  }
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatSetPreallocationCOO_MPIBinBCSR(Mat mat, PetscCount ncoo,
                                                              const PetscInt coo_i[], const PetscInt coo_j[])
{
  Mat_MPIBinBCSR *b    = MPIBinBCSR(mat);
  MPI_Comm        comm = PetscObjectComm((PetscObject)mat);

  PetscFunctionBegin;
  PetscCall(MatMPIBinBCSRSetUpLayouts(mat));
  PetscCheck(mat->rmap->bs == mat->cmap->bs, comm, PETSC_ERR_ARG_INCOMP,
             "MATMPIBINBCSR needs equal row and column block sizes");
  PetscCall(MatMPIBinBCSRResetParts(mat));
  const PetscInt rstart = mat->rmap->rstart, rend = mat->rmap->rend, cstart = mat->cmap->rstart,
                 cend = mat->cmap->rend;
  const PetscInt M = mat->rmap->N, N = mat->cmap->N, bs = mat->cmap->bs, m = mat->rmap->n;
  auto          *coo = new MPIBinBCSRCoo();
  b->coo             = coo;
  coo->n             = ncoo;

  /* With the COO mirror, entry ncoo + t is the transpose of entry mirror_of[t] and reads its value;
     it is routed like any other (its row may be another rank's). */
  std::vector<PetscCount> mirror_of;
  if (b->coo_mirror) {
    PetscBool congruent; /* the same answer on every rank */
    PetscCall(PetscLayoutCompare(mat->rmap, mat->cmap, &congruent));
    PetscCheck(congruent, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_SIZ,
               "The COO mirror needs a square matrix with equal row and column layouts");
    for (PetscCount k = 0; k < ncoo; k++)
      if (coo_i[k] >= 0 && coo_j[k] >= 0 && coo_i[k] / bs != coo_j[k] / bs) mirror_of.push_back(k);
  }
  const PetscCount nall   = ncoo + static_cast<PetscCount>(mirror_of.size());
  auto             src_of = [&](PetscCount e) { return e < ncoo ? e : mirror_of[e - ncoo]; };
  auto             row_of = [&](PetscCount e) { return e < ncoo ? coo_i[e] : coo_j[mirror_of[e - ncoo]]; };
  auto             col_of = [&](PetscCount e) { return e < ncoo ? coo_j[e] : coo_i[mirror_of[e - ncoo]]; };

  std::vector<PetscCount>  own;
  std::vector<PetscMPIInt> dest;
  std::vector<PetscInt>    send_i, send_j;
  for (PetscCount e = 0; e < nall; e++) {
    const PetscInt   i = row_of(e), j = col_of(e);
    const PetscCount k = src_of(e);
    if (i < 0 || j < 0) continue; /* PETSc's convention: negative indices are ignored */
    PetscCheck(i < M && j < N, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "COO entry %" PetscCount_FMT " (%" PetscInt_FMT ",%" PetscInt_FMT
               ") out of range for a %" PetscInt_FMT " x %" PetscInt_FMT " matrix",
               k, i, j, M, N);
    if (i >= rstart && i < rend) {
      own.push_back(e);
    } else {
      PetscMPIInt owner;
      PetscCall(PetscLayoutFindOwner(mat->rmap, i, &owner));
      dest.push_back(owner);
      coo->send_from.push_back(k);
      send_i.push_back(i);
      send_j.push_back(j);
    }
  }
  PetscCall(
    MatMPIBinBCSRBuildSendSF(comm, static_cast<PetscInt>(dest.size()), dest.data(), &coo->sf, &coo->nrecv));
  std::vector<PetscInt> recv_i(coo->nrecv), recv_j(coo->nrecv);
  PetscCall(PetscSFReduceBegin(coo->sf, MPIU_INT, send_i.data(), recv_i.data(), MPI_REPLACE));
  PetscCall(PetscSFReduceBegin(coo->sf, MPIU_INT, send_j.data(), recv_j.data(), MPI_REPLACE));
  PetscCall(PetscSFReduceEnd(coo->sf, MPIU_INT, send_i.data(), recv_i.data(), MPI_REPLACE));
  PetscCall(PetscSFReduceEnd(coo->sf, MPIU_INT, send_j.data(), recv_j.data(), MPI_REPLACE));

  /* route every entry of this rank's rows to A or B */
  std::vector<PetscInt> ai, aj, bi, bj;
  auto                  route = [&](PetscInt i, PetscInt j, PetscCount from) {
    if (j >= cstart && j < cend) {
      ai.push_back(i - rstart);
      aj.push_back(j - cstart);
      coo->a_from.push_back(from);
    } else {
      bi.push_back(i - rstart);
      bj.push_back(j);
      coo->b_from.push_back(from);
    }
  };
  for (PetscCount e : own) route(row_of(e), col_of(e), src_of(e));
  for (PetscInt r = 0; r < coo->nrecv; r++) route(recv_i[r], recv_j[r], ncoo + r);

  b->garray.resize(bj.size());
  for (std::size_t k = 0; k < bj.size(); k++) b->garray[k] = bj[k] / bs;
  std::sort(b->garray.begin(), b->garray.end());
  b->garray.erase(std::unique(b->garray.begin(), b->garray.end()), b->garray.end());
  b->compressed = PETSC_TRUE;
  for (auto &j : bj) PetscCall(MatMPIBinBCSRGhostIndex(mat, j, &j));

  PetscCall(MatMPIBinBCSRCreatePart(mat, m, mat->cmap->n, &b->A));
  PetscCall(MatSetPreallocationCOO(b->A, static_cast<PetscCount>(ai.size()), ai.data(), aj.data()));
  PetscCall(MatMPIBinBCSRCreatePart(mat, m, static_cast<PetscInt>(b->garray.size()) * bs, &b->B));
  PetscCall(MatSetPreallocationCOO(b->B, static_cast<PetscCount>(bi.size()), bi.data(), bj.data()));
  PetscCall(MatMPIBinBCSRSetUpScatter(mat));
  coo->sendbuf.resize(coo->send_from.size());
  coo->recvbuf.resize(coo->nrecv);
  /* BIN-BCSR parts read the caller's values and the received ones directly through their composed
     maps; other inner types get their own COO lists copied out at every refill. */
  PetscBool abin, bbin;
  PetscCall(PetscObjectTypeCompare((PetscObject)b->A, MATSEQBINBCSR, &abin));
  PetscCall(PetscObjectTypeCompare((PetscObject)b->B, MATSEQBINBCSR, &bbin));
  coo->composed = abin && bbin ? PETSC_TRUE : PETSC_FALSE;
  if (coo->composed) {
    PetscCall(MatSeqBinBCSRComposeCOO(b->A, coo->a_from.data(), ncoo, ncoo + coo->nrecv));
    PetscCall(MatSeqBinBCSRComposeCOO(b->B, coo->b_from.data(), ncoo, ncoo + coo->nrecv));
    std::vector<PetscCount>().swap(coo->a_from);
    std::vector<PetscCount>().swap(coo->b_from);
  } else {
    coo->a_v.resize(coo->a_from.size());
    coo->b_v.resize(coo->b_from.size());
  }
  mat->preallocated = PETSC_TRUE;
  mat->assembled    = PETSC_FALSE;
  PetscFunctionReturn(0);
}

namespace {

/* The refill of both parts from the caller's values v (double, or float for
   MatBinBCSRSetValuesCOOSingle) and the entries other ranks send. */
template <typename S> PetscErrorCode SetValuesCOO_MPIBinBCSR(Mat mat, const S v[], InsertMode mode)
{
  Mat_MPIBinBCSR *b   = MPIBinBCSR(mat);
  MPIBinBCSRCoo  *coo = b->coo;

  PetscFunctionBegin;
  PetscCheck(coo, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_WRONGSTATE,
             "Call MatSetPreallocationCOO() first");
  /* no values on this rank: its entries are zeros (as for the seq type); the exchange stays collective */
  std::vector<S> zeros;
  if (!v) {
    zeros.assign((std::size_t)coo->n, (S)0);
    v = zeros.data();
  }
  for (std::size_t q = 0; q < coo->send_from.size(); q++) coo->sendbuf[q] = v[coo->send_from[q]];
  PetscCall(PetscSFReduceBegin(coo->sf, MPIU_SCALAR, coo->sendbuf.data(), coo->recvbuf.data(), MPI_REPLACE));
  const PetscCount n = coo->n;
  if (coo->composed) { /* each part gathers from v and recvbuf itself: no intermediate copy */
    PetscCall(PetscSFReduceEnd(coo->sf, MPIU_SCALAR, coo->sendbuf.data(), coo->recvbuf.data(), MPI_REPLACE));
    if constexpr (std::is_same<S, float>::value) {
      PetscCall(MatSetValuesCOOTwoSourcesSingle_SeqBinBCSR(b->A, v, n, coo->recvbuf.data(), mode));
      PetscCall(MatSetValuesCOOTwoSourcesSingle_SeqBinBCSR(b->B, v, n, coo->recvbuf.data(), mode));
    } else {
      PetscCall(MatSetValuesCOOTwoSources_SeqBinBCSR(b->A, v, n, coo->recvbuf.data(), mode));
      PetscCall(MatSetValuesCOOTwoSources_SeqBinBCSR(b->B, v, n, coo->recvbuf.data(), mode));
    }
  } else {
    /* the local entries are gathered while the others travel */
    for (std::size_t k = 0; k < coo->a_from.size(); k++)
      if (coo->a_from[k] < n) coo->a_v[k] = v[coo->a_from[k]];
    for (std::size_t k = 0; k < coo->b_from.size(); k++)
      if (coo->b_from[k] < n) coo->b_v[k] = v[coo->b_from[k]];
    PetscCall(PetscSFReduceEnd(coo->sf, MPIU_SCALAR, coo->sendbuf.data(), coo->recvbuf.data(), MPI_REPLACE));
    for (std::size_t k = 0; k < coo->a_from.size(); k++)
      if (coo->a_from[k] >= n) coo->a_v[k] = coo->recvbuf[coo->a_from[k] - n];
    for (std::size_t k = 0; k < coo->b_from.size(); k++)
      if (coo->b_from[k] >= n) coo->b_v[k] = coo->recvbuf[coo->b_from[k] - n];
    PetscCall(MatSetValuesCOO(b->A, coo->a_v.data(), mode));
    PetscCall(MatSetValuesCOO(b->B, coo->b_v.data(), mode));
  }
  b->coo_just_assembled = PETSC_TRUE; /* MatSetValuesCOO() assembles mat next; nothing is stashed */
  PetscFunctionReturn(0);
}

} // namespace

PETSC_INTERN PetscErrorCode MatSetValuesCOO_MPIBinBCSR(Mat mat, const PetscScalar v[], InsertMode mode)
{
  return SetValuesCOO_MPIBinBCSR(mat, v, mode);
}

/* The parts of binbcsr read the floats themselves; parts of another type get them widened (a_v, b_v). */
PETSC_INTERN PetscErrorCode MatBinBCSRSetValuesCOOSingle_MPIBinBCSR(Mat mat, const float v[], InsertMode mode)
{
  return SetValuesCOO_MPIBinBCSR(mat, v, mode);
}
