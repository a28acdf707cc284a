#include "host_bins.h"
#include "mat_binbcsr/kernels/binbcsr_layout.h"

#include <algorithm>
#include <stdexcept>

namespace binbcsr {
namespace device {

Layout HostBins::layout() const
{
  Layout L;
  L.bs        = bs;
  L.bw        = bw;
  L.mbs       = mbs;
  L.symmetric = symmetric;
  L.bin_start = bin_start.data();
  L.col       = col.data();
  return L;
}

long HostBins::slot(int r, int c) const
{
  const auto &rs = row_slots[r];
  auto        it = std::lower_bound(rs.begin(), rs.end(), std::make_pair(c, -1));
  return it != rs.end() && it->first == c ? it->second : -1;
}

namespace {
/* Symmetric storage: slot k of lane l of each bin chosen greedily so that no two lanes scatter to one
   column in one slot group (the diagonal block and padding do not scatter). */
void colour_bins(HostBins &B, const int *ptr, const int *cols)
{
  const int nbins = (B.mbs + B.bw - 1) / B.bw;
  B.bin_start.assign(nbins + 1, 0);
  B.col.clear();
  for (int b = 0; b < nbins; b++) {
    std::vector<std::vector<int>> lane_col(B.bw); /* lane_col[l][k]: column at slot k, -1 free */
    std::vector<std::vector<int>> scatter;        /* scatter[k]: columns scattered to at slot k */
    for (int l = 0; l < B.bw; l++) {
      const int r = b * B.bw + l;
      if (r >= B.mbs) break;
      for (int p = ptr[r]; p < ptr[r + 1]; p++) {
        const int c = cols[p];
        if (c < r) continue;
        int k = 0;
        for (;; k++) {
          if (k >= (int)scatter.size()) scatter.emplace_back();
          if (k < (int)lane_col[l].size() && lane_col[l][k] >= 0) continue;
          if (c != r && std::find(scatter[k].begin(), scatter[k].end(), c) != scatter[k].end()) continue;
          break;
        }
        if (k >= (int)lane_col[l].size()) lane_col[l].resize(k + 1, -1);
        lane_col[l][k] = c;
        if (c != r) scatter[k].push_back(c);
      }
    }
    size_t len = 0;
    for (auto &lc : lane_col) len = std::max(len, lc.size());
    const int s0 = (int)B.col.size();
    B.col.resize(s0 + len * B.bw);
    for (int l = 0; l < B.bw; l++) {
      const int r = b * B.bw + l, own = r < B.mbs ? r : B.mbs - 1;
      for (size_t k = 0; k < len; k++) {
        const int c = k < lane_col[l].size() ? lane_col[l][k] : -1;
        const int s = s0 + (int)k * B.bw + l;
        B.col[s]    = c >= 0 ? c : own;
        if (c >= 0) B.row_slots[r].push_back({c, s});
      }
    }
    B.bin_start[b + 1] = (int)B.col.size();
  }
  for (auto &rs : B.row_slots) std::sort(rs.begin(), rs.end());
}
} // namespace

HostBins bins_from_bcsr(int bs, int mbs, const int *ptr, const int *cols, const double *vals, int bw,
                        bool symmetric)
{
  if (bs < 1 || bs > 8 || bw < 1 || bw > 32 || mbs < 1)
    throw std::invalid_argument("bins_from_bcsr: needs 1 <= bs <= 8, 1 <= bw <= 32, mbs >= 1");
  HostBins B;
  B.bs        = bs;
  B.bw        = bw;
  B.mbs       = mbs;
  B.symmetric = symmetric;
  B.row_slots.resize(mbs);
  if (symmetric) colour_bins(B, ptr, cols);
  else {
    B.bin_start.resize((mbs + bw - 1) / bw + 1);
    const long nslots = binbcsr::bin_starts<int>(ptr, mbs, bw, B.bin_start.data());
    B.col.resize(nslots);
    binbcsr::bin_columns<int>(ptr, cols, mbs, bw, B.bin_start.data(), B.col.data(), nullptr);
    for (int r = 0; r < mbs; r++)
      for (int k = 0; k < ptr[r + 1] - ptr[r]; k++)
        B.row_slots[r].push_back(
          {cols[ptr[r] + k], (int)binbcsr::row_slot<int>(B.bin_start.data(), bw, r, k)});
  }
  const int bs2 = bs * bs;
  B.val.assign(B.col.size() * bs2, 0.0);
  if (vals)
    for (int r = 0; r < mbs; r++)
      for (int p = ptr[r]; p < ptr[r + 1]; p++) {
        const long s = B.slot(r, cols[p]);
        if (s < 0) continue; /* below the diagonal, symmetric storage */
        for (int e = 0; e < bs2; e++) B.val[binbcsr::value_index(s, e, bw, bs2)] = vals[(long)p * bs2 + e];
      }
  return B;
}

HostGather gather_from_coo(const HostBins &B, long ncoo, const int *ci, const int *cj)
{
  const int  bs = B.bs, bs2 = bs * bs;
  const long nv = (long)B.col.size() * bs2;
  HostGather G;
  G.ncoo = ncoo;
  std::vector<long> vof(ncoo, -1);
  G.jmap.assign(nv + 1, 0);
  for (long p = 0; p < ncoo; p++) {
    const int R = ci[p] / bs, C = cj[p] / bs;
    if (ci[p] < 0 || cj[p] < 0 || R >= B.mbs || C >= B.mbs || (B.symmetric && C < R)) continue;
    const long s = B.slot(R, C);
    if (s < 0) continue;
    vof[p] = binbcsr::value_index(s, (ci[p] % bs) * bs + cj[p] % bs, B.bw, bs2);
    G.jmap[vof[p] + 1]++;
  }
  for (long v = 0; v < nv; v++) G.jmap[v + 1] += G.jmap[v];
  G.perm.resize(G.jmap[nv]);
  std::vector<int> fill(G.jmap.begin(), G.jmap.end() - 1);
  for (long p = 0; p < ncoo; p++)
    if (vof[p] >= 0) G.perm[fill[vof[p]]++] = (int)p;
  return G;
}

} // namespace device
} // namespace binbcsr
