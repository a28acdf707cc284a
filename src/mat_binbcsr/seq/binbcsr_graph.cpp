/* The block graph of a MATSEQBINBCSR matrix: one node per block row, one edge weight per stored block,
   the sum of the block's absolute values. PETSc's MatCreateGraph reduces an AIJ matrix of block size
   bs > 1 to this graph entry by entry before it symmetrises, scales and filters; PCGAMG asked it of the
   matrix's AIJ shadow, a copy of every value (linear_38k: 19 MB). Made here from the blocks, the graph
   has a bs^2-th of the entries, and MatCreateGraph of it (block size 1, nothing to reduce) runs only
   the rest of PETSc's steps: PCGAMG aggregates the same graph (tests/unit/mat_binbcsr/mat_core/graph.cpp
   compares the two entry for entry). With the Galerkin product (binbcsr_ptap.cpp) GAMG's set-up on
   one rank needs no shadow at all. */
#include "binbcsr.h"

namespace {
/* Sum of |entry| of the block at vb, entry (i, j) in the order PETSc's reduction adds them: row i of
   the block, then column j (a transposed block: (j, i) of the stored one). */
template <typename V> double BlockWeight(const V *val, PetscInt vb, bool t, PetscInt bs, PetscInt bw)
{
  double w = 0;
  for (PetscInt i = 0; i < bs; i++)
    for (PetscInt j = 0; j < bs; j++) w += PetscAbsReal((PetscReal)val[FullRowEntry(vb, t, i, j, bs, bw)]);
  return w;
}
} // namespace

/* G0: a new SeqAIJ of mbs x nbs, block size 1, the weights of A's full block rows (both triangles with
   symmetric storage), A's symmetry flags. */
PetscErrorCode MatSeqBinBCSRBlockGraph(Mat A, Mat *G0)
{
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt  bs = a->bs, bw = a->bw, mbs = a->mbs;
  PetscInt       *nnz, *idx, n = 0, total = 0;
  PetscScalar    *v;
  Mat             G;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "The graph of a MATSEQBINBCSR matrix needs it assembled");
  if (a->sym) PetscCall(MatSeqBinBCSRBuildLowerIndex(a));
  PetscCall(PetscMalloc1(mbs, &nnz));
  for (PetscInt br = 0; br < mbs; br++) {
    nnz[br] = a->row_nz[br] + (a->sym ? a->lower_off[br + 1] - a->lower_off[br] : 0);
    total += nnz[br];
  }
  PetscCall(MatCreate(PETSC_COMM_SELF, &G));
  PetscCall(MatSetSizes(G, mbs, a->nbs, mbs, a->nbs));
  PetscCall(MatSetType(G, MATSEQAIJ));
  PetscCall(MatSeqAIJSetPreallocation(G, 0, nnz));
  PetscCall(PetscFree(nnz));
  PetscCall(PetscMalloc1(PetscMax(total, 1), &idx));
  for (PetscInt br = 0; br < mbs; br++)
    ForEachFullRowBlock(a, br, [&](PetscInt bc, PetscInt, bool) { idx[n++] = bc; });
  PetscCall(MatSeqAIJSetColumnIndices(G, idx)); /* ascending per row: ForEachFullRowBlock's order */
  PetscCall(PetscFree(idx));
  PetscCall(MatSeqAIJGetArray(G, &v));
  n = 0;
  for (PetscInt br = 0; br < mbs; br++)
    ForEachFullRowBlock(a, br, [&](PetscInt, PetscInt vb, bool t) {
      v[n++] = a->val ? BlockWeight(a->val, vb, t, bs, bw) : BlockWeight(a->valf, vb, t, bs, bw);
    });
  PetscCall(MatSeqAIJRestoreArray(G, &v));
  PetscCall(MatAssemblyBegin(G, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(G, MAT_FINAL_ASSEMBLY));
  /* as the shadow had them: MatCreateGraph does not symmetrise a graph known to be symmetric */
  PetscCall(MatPropagateSymmetryOptions(A, G));
  *G0 = G;
  PetscFunctionReturn(0);
}
