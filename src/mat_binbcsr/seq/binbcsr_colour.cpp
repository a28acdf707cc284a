/*
   MATSEQBINBCSR symmetric storage: the slot order inside a bin.

   The product with the upper triangle scatters y_c += block^T x_r for every off-diagonal block
   (r, c). The lanes of a bin run in lock step over the slot groups k (SIMD lanes, a GPU warp), so two
   lanes of one slot group must never scatter into the same column c. Inside a bin this is a
   bipartite edge colouring: lanes on one side, columns on the other, one edge per off-diagonal block,
   slot groups as colours. By Koenig's theorem max-degree colours suffice, where the degree is the
   lane's count of off-diagonal blocks or the column's multiplicity in the bin, whichever is larger;
   a greedy colouring may need 2*Delta - 1. The alternating-path algorithm below reaches Delta: to
   colour edge (u, v), take a colour a free at lane u and b free at column v; if a is taken at v,
   swap a and b along the alternating a/b path that starts at v (it cannot reach u, which has no a
   edge), which frees a at v. The diagonal block and the padding (zero values, the lane's own row as
   column, so no scatter) fill the slots the colouring left free in each lane. So the bin needs
   max(Delta, longest row) slot groups: the same as full storage pads to unless a column occurs in
   more lanes of the bin than the longest row is long (end rows of a band).
*/
#include "binbcsr.h"
#include <algorithm>

/* The colouring where it costs no slot: slot group k holds the blocks of one column offset c - r in
   every lane, the offsets ascending (the diagonal block at offset 0). Two lanes of a group then never
   share a column (their rows differ), and the groups of a bin of grid rows read consecutive columns:
   the products load x and update y there instead of gathering and scattering (a Koenig colouring of
   the 48^3 stencil left 30% of the groups to gathers). It takes as many groups as the bin has
   distinct offsets, which is at least the L of the Koenig colouring; returns that count where it is L
   (the bin's rows share their offsets: grids, structured meshes), else 0. A lane without a block of
   some offset gets padding there (zeros, its own row as column). */
static PetscInt ColourBinByOffset(PetscInt bw, PetscInt r0, PetscInt mbs, const PetscInt bi[],
                                  const PetscInt bj[], const std::vector<PetscInt> &first, PetscInt L,
                                  std::vector<PetscInt> &slot_col, std::vector<PetscInt> &entry_k)
{
  const PetscInt        nl = PetscMin(bw, mbs - r0);
  std::vector<PetscInt> offsets;
  for (PetscInt l = 0; l < nl; l++) {
    const PetscInt r = r0 + l;
    for (PetscInt q = first[l]; q < bi[r + 1]; q++) {
      offsets.push_back(bj[q] - r);
      if ((PetscInt)offsets.size() > 4 * L) { /* keep it short for a bin that will not fit */
        std::sort(offsets.begin(), offsets.end());
        offsets.erase(std::unique(offsets.begin(), offsets.end()), offsets.end());
        if ((PetscInt)offsets.size() > L) return 0;
      }
    }
  }
  std::sort(offsets.begin(), offsets.end());
  offsets.erase(std::unique(offsets.begin(), offsets.end()), offsets.end());
  if ((PetscInt)offsets.size() != L) return 0;
  /* The group order: offsets less than bw apart update overlapping ranges of y, and a group that
     loads y right after the previous group stored an overlapping range waits for that store to
     complete (the load cannot take its data from the store queue). So the runs of close offsets
     (47, 48, 49 on a 48^3 grid) are dealt out round robin: the k-th offset of every run, then the
     (k+1)-th. group_of[i]: the slot group of the i-th smallest offset. */
  std::vector<PetscInt> group_of(L), run_start;
  for (PetscInt i = 0; i < L; i++)
    if (!i || offsets[i] - offsets[i - 1] >= bw) run_start.push_back(i);
  run_start.push_back(L);
  {
    PetscInt g = 0;
    for (PetscInt k = 0; g < L; k++)
      for (size_t j = 0; j + 1 < run_start.size(); j++)
        if (run_start[j] + k < run_start[j + 1]) group_of[run_start[j] + k] = g++;
  }
  slot_col.assign((size_t)L * bw, 0);
  for (PetscInt l = 0; l < bw; l++) {
    const PetscInt r   = r0 + l;
    const PetscInt own = r < mbs ? r : mbs - 1;
    for (PetscInt k = 0; k < L; k++) slot_col[k * bw + l] = own;
    if (l >= nl) continue;
    for (PetscInt q = first[l]; q < bi[r + 1]; q++) {
      const PetscInt k =
        group_of[std::lower_bound(offsets.begin(), offsets.end(), bj[q] - r) - offsets.begin()];
      slot_col[k * bw + l] = bj[q];
      entry_k.push_back(k);
    }
  }
  return L;
}

PetscInt MatSeqBinBCSRColourBin(PetscInt bw, PetscInt r0, PetscInt mbs, const PetscInt bi[],
                                const PetscInt bj[], std::vector<PetscInt> &slot_col,
                                std::vector<PetscInt> &entry_k, std::vector<PetscInt> &colid)
{
  const PetscInt        nl = PetscMin(bw, mbs - r0);
  std::vector<PetscInt> first(nl), cols_used, mult, lane_at, col_at;
  PetscInt              maxdeg = 0, maxlen = 0, D, L;

  /* the bin's columns get local ids; degrees */
  for (PetscInt l = 0; l < nl; l++) {
    const PetscInt r = r0 + l;
    PetscInt       p = bi[r], deg = 0;
    while (p < bi[r + 1] && bj[p] < r) p++;
    first[l] = p;
    maxlen   = PetscMax(maxlen, bi[r + 1] - p);
    for (PetscInt q = p; q < bi[r + 1]; q++) {
      const PetscInt c = bj[q];
      if (c == r) continue;
      deg++;
      if (colid[c] < 0) {
        colid[c] = (PetscInt)cols_used.size();
        cols_used.push_back(c);
        mult.push_back(0);
      }
      mult[colid[c]]++;
    }
    maxdeg = PetscMax(maxdeg, deg);
  }
  D = maxdeg;
  for (PetscInt m : mult) D = PetscMax(D, m);
  L = PetscMax(D, maxlen);
  {
    const PetscInt La = ColourBinByOffset(bw, r0, mbs, bi, bj, first, L, slot_col, entry_k);
    if (La > 0) {
      for (PetscInt c : cols_used) colid[c] = -1;
      return La;
    }
  }

  /* Koenig colouring of the off-diagonal blocks with D colours */
  const PetscInt ncols = (PetscInt)cols_used.size();
  lane_at.assign((size_t)nl * D, -1);   /* [lane][colour] -> local column */
  col_at.assign((size_t)ncols * D, -1); /* [column][colour] -> lane */
  std::vector<PetscInt> path_lane, path_col, path_colour;
  for (PetscInt u = 0; u < nl; u++) {
    const PetscInt r = r0 + u;
    for (PetscInt q = first[u]; q < bi[r + 1]; q++) {
      if (bj[q] == r) continue;
      const PetscInt v = colid[bj[q]];
      PetscInt       a = 0, b = 0;
      while (lane_at[u * D + a] >= 0) a++; /* exists: u has fewer than D coloured edges so far */
      while (col_at[v * D + b] >= 0) b++;
      if (col_at[v * D + a] >= 0) { /* swap a and b along the a/b path from v */
        path_lane.clear();
        path_col.clear();
        path_colour.clear();
        PetscInt cur = v;
        for (;;) {
          const PetscInt w = col_at[cur * D + a];
          if (w < 0) break;
          path_lane.push_back(w);
          path_col.push_back(cur);
          path_colour.push_back(a);
          const PetscInt x = lane_at[w * D + b];
          if (x < 0) break;
          path_lane.push_back(w);
          path_col.push_back(x);
          path_colour.push_back(b);
          cur = x;
        }
        for (size_t e = 0; e < path_lane.size(); e++) {
          lane_at[path_lane[e] * D + path_colour[e]] = -1;
          col_at[path_col[e] * D + path_colour[e]]   = -1;
        }
        for (size_t e = 0; e < path_lane.size(); e++) {
          const PetscInt nc              = path_colour[e] == a ? b : a;
          lane_at[path_lane[e] * D + nc] = path_col[e];
          col_at[path_col[e] * D + nc]   = path_lane[e];
        }
      }
      lane_at[u * D + a] = v;
      col_at[v * D + a]  = u;
    }
  }

  /* slots: coloured blocks at their colour, then the diagonal block and padding in the free slots */
  slot_col.assign((size_t)L * bw, 0);
  for (PetscInt l = 0; l < bw; l++) {
    const PetscInt    r      = r0 + l;
    const PetscInt    own    = r < mbs ? r : mbs - 1;
    PetscInt          diag_k = -1;
    std::vector<char> used(L, 0);
    if (l < nl)
      for (PetscInt k = 0; k < D; k++)
        if (lane_at[l * D + k] >= 0) {
          slot_col[k * bw + l] = cols_used[lane_at[l * D + k]];
          used[k]              = 1;
        }
    for (PetscInt k = 0; k < L; k++) {
      if (used[k]) continue;
      slot_col[k * bw + l] = own;
      if (l < nl && diag_k < 0 && first[l] < bi[r + 1] && bj[first[l]] == r) diag_k = k;
    }
    if (l >= nl) continue;
    for (PetscInt q = first[l]; q < bi[r + 1]; q++) {
      if (bj[q] == r) {
        entry_k.push_back(diag_k);
        continue;
      }
      const PetscInt v = colid[bj[q]];
      PetscInt       k = 0;
      while (lane_at[l * D + k] != v) k++;
      entry_k.push_back(k);
    }
  }
  for (PetscInt c : cols_used) colid[c] = -1;
  return L;
}
