// Host-side matrices of the GPU benchmark (examples/gpu/binbcsr_gpu_bench.cu): the 27-point block
// stencil, PETSc binary files, the scalar CSR every cuSPARSE format starts from, and the bins of
// src/mat_binbcsr/kernels/binbcsr_layout.h. Plain C++17; a failed read exits with a message.
#pragma once
#include "mat_binbcsr/kernels/binbcsr_layout.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace gpu_bench {

// A square matrix of bs x bs blocks in block CSR (row-major blocks), host side.
struct BlockMatrix {
  std::string         name;
  int                 bs = 3, mbs = 0;
  std::vector<int>    ptr, col;
  std::vector<double> val;
  long                nblocks() const { return (long)col.size(); }
  int                 n() const { return mbs * bs; }
};

uint64_t mix(uint64_t h)
{
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ULL;
  return h ^ (h >> 33);
}
double unit_random(uint64_t key) { return (double)(mix(key) >> 11) * (2.0 / 9007199254740992.0) - 1.0; }

// 27-point block stencil on n^3 nodes: block (i, j) = -(1 + 0.5 u) I - 0.2 S for neighbours, with u and the
// symmetric S drawn from the unordered pair {i, j} (so A is symmetric), the diagonal block a multiple of I
// larger than the row's off-diagonal absolute sum (so A is SPD).
BlockMatrix stencil_matrix(int n)
{
  BlockMatrix A;
  A.name = "stencil" + std::to_string(n);
  A.bs   = 3;
  A.mbs  = n * n * n;
  A.ptr.assign(1, 0);
  for (int z = 0; z < n; z++)
    for (int y = 0; y < n; y++)
      for (int x = 0; x < n; x++) {
        const long i        = ((long)z * n + y) * n + x;
        long       diag_pos = -1;
        for (int dz = -1; dz <= 1; dz++)
          for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
              if (z + dz < 0 || z + dz >= n || y + dy < 0 || y + dy >= n || x + dx < 0 || x + dx >= n)
                continue;
              const long j = ((long)(z + dz) * n + y + dy) * n + x + dx;
              A.col.push_back((int)j);
              const size_t at = A.val.size();
              A.val.resize(at + 9, 0.0);
              if (j == i) {
                diag_pos = (long)at;
                continue;
              }
              const uint64_t key =
                (uint64_t)std::min(i, j) * 0x9E3779B97F4A7C15ULL + (uint64_t)std::max(i, j);
              const double u = unit_random(key * 7 + 1);
              double       s[6];
              for (int k = 0; k < 6; k++) s[k] = unit_random(key * 7 + 2 + k);
              const double S[9] = {s[0], s[1], s[2], s[1], s[3], s[4], s[2], s[4], s[5]};
              for (int e = 0; e < 9; e++) A.val[at + e] = (e % 4 == 0 ? -(1.0 + 0.5 * u) : 0.0) - 0.2 * S[e];
            }
        A.ptr.push_back((int)A.col.size());
        // Dominance row by row: the largest row sum of |off-diagonal entries| over the block row, plus 1.
        double rowmax = 0.0;
        for (int r = 0; r < 3; r++) {
          double rs = 0.0;
          for (long p = A.ptr[A.ptr.size() - 2]; p < A.ptr.back(); p++)
            if (A.col[p] != i)
              for (int c = 0; c < 3; c++) rs += std::fabs(A.val[(size_t)p * 9 + 3 * r + c]);
          rowmax = std::max(rowmax, rs);
        }
        for (int d = 0; d < 3; d++) A.val[diag_pos + 4 * d] = rowmax + 1.0;
      }
  return A;
}

uint32_t big_endian32(const unsigned char *p)
{
  return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

// A PETSc binary matrix (big-endian: class id 1211216, M, N, nz, row lengths, columns, values), grouped
// into bs x bs blocks (entries the blocks hold but the file does not are zeros).
BlockMatrix read_petsc_binary(const std::string &path, int bs)
{
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    std::fprintf(stderr, "cannot open %s\n", path.c_str());
    std::exit(2);
  }
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  auto                       need = [&](size_t n) {
    if (bytes.size() < n) {
      std::fprintf(stderr, "%s: truncated PETSc binary matrix\n", path.c_str());
      std::exit(2);
    }
  };
  need(16);
  const uint32_t id = big_endian32(&bytes[0]);
  const long     M = big_endian32(&bytes[4]), N = big_endian32(&bytes[8]), nz = big_endian32(&bytes[12]);
  if (id != 1211216 || M != N || M % bs || M <= 0 || nz < 0) {
    std::fprintf(stderr, "%s: not a square PETSc binary matrix with block size %d (class id %u, %ld x %ld)\n",
                 path.c_str(), bs, id, M, N);
    std::exit(2);
  }
  need(16 + 4 * (size_t)M + 12 * (size_t)nz);
  std::vector<long> rowptr(M + 1, 0);
  for (long r = 0; r < M; r++) rowptr[r + 1] = rowptr[r] + big_endian32(&bytes[16 + 4 * r]);
  if (rowptr[M] != nz) {
    std::fprintf(stderr, "%s: row lengths do not add up to nz\n", path.c_str());
    std::exit(2);
  }
  const unsigned char *cols = &bytes[16 + 4 * M], *vals = cols + 4 * nz;
  BlockMatrix          A;
  A.name = path.substr(path.find_last_of('/') + 1);
  A.bs   = bs;
  A.mbs  = (int)(M / bs);
  A.ptr.assign(1, 0);
  std::vector<long> slot_of(A.mbs, -1);
  for (int br = 0; br < A.mbs; br++) {
    std::vector<int> bcols;
    for (long r = (long)br * bs; r < (long)(br + 1) * bs; r++)
      for (long p = rowptr[r]; p < rowptr[r + 1]; p++)
        bcols.push_back((int)(big_endian32(cols + 4 * p) / bs));
    std::sort(bcols.begin(), bcols.end());
    bcols.erase(std::unique(bcols.begin(), bcols.end()), bcols.end());
    const size_t first = A.col.size();
    for (size_t k = 0; k < bcols.size(); k++) {
      if (bcols[k] < 0 || bcols[k] >= A.mbs) {
        std::fprintf(stderr, "%s: column out of range\n", path.c_str());
        std::exit(2);
      }
      slot_of[bcols[k]] = (long)(first + k);
    }
    A.col.insert(A.col.end(), bcols.begin(), bcols.end());
    A.val.resize(A.col.size() * bs * bs, 0.0);
    for (long r = (long)br * bs; r < (long)(br + 1) * bs; r++)
      for (long p = rowptr[r]; p < rowptr[r + 1]; p++) {
        const uint32_t c = big_endian32(cols + 4 * p);
        uint64_t       u = 0;
        for (int k = 0; k < 8; k++) u = u << 8 | vals[8 * p + k];
        double v;
        std::memcpy(&v, &u, 8);
        A.val[(size_t)slot_of[c / bs] * bs * bs + (r % bs) * bs + c % bs] = v;
      }
    A.ptr.push_back((int)A.col.size());
  }
  return A;
}

// Scalar CSR of the block matrix (every entry of every block, zeros included: all formats store the same).
struct ScalarCSR {
  std::vector<int>    ptr, col;
  std::vector<double> val;
};
ScalarCSR scalar_csr(const BlockMatrix &A)
{
  const int bs = A.bs;
  ScalarCSR S;
  S.ptr.assign(1, 0);
  for (int br = 0; br < A.mbs; br++)
    for (int i = 0; i < bs; i++) {
      for (int p = A.ptr[br]; p < A.ptr[br + 1]; p++)
        for (int j = 0; j < bs; j++) {
          S.col.push_back(A.col[p] * bs + j);
          S.val.push_back(A.val[(size_t)p * bs * bs + i * bs + j]);
        }
      S.ptr.push_back((int)S.col.size());
    }
  return S;
}

// The bins of a block CSR pattern (bs 1 for BIN-CSR), values in the tile layout, in V.
template <typename V> struct Bins {
  int              bs, bw, mbs;
  std::vector<int> start, col;
  std::vector<V>   val;
  long             nslots() const { return (long)col.size(); }
};
template <typename V>
Bins<V> make_bins(const std::vector<int> &ptr, const std::vector<int> &col, const std::vector<double> &val,
                  int bs, int mbs, int bw)
{
  Bins<V> B;
  B.bs  = bs;
  B.bw  = bw;
  B.mbs = mbs;
  B.start.resize((mbs + bw - 1) / bw + 1);
  const long nslots = binbcsr::bin_starts<int>(ptr.data(), mbs, bw, B.start.data());
  B.col.resize(nslots);
  binbcsr::bin_columns<int>(ptr.data(), col.data(), mbs, bw, B.start.data(), B.col.data(), nullptr);
  B.val.assign((size_t)nslots * bs * bs, (V)0);
  for (int r = 0; r < mbs; r++)
    for (int k = 0; k < ptr[r + 1] - ptr[r]; k++) {
      const long s = binbcsr::row_slot<int>(B.start.data(), bw, r, k);
      for (int e = 0; e < bs * bs; e++)
        B.val[binbcsr::value_index(s, e, bw, bs * bs)] = (V)val[(size_t)(ptr[r] + k) * bs * bs + e];
    }
  return B;
}

// The compact form scripts/gpu_check ships the driver matrices in (a GPU machine receives at most 64 MiB
// of the tree; PETSc binary costs 12 bytes a nonzero, this 4 + 4/bs^2): "BBM1", then int32 bs, mbs,
// nblocks, ptr[mbs + 1], col[nblocks], float32 values[nblocks * bs^2] (row-major blocks). The values
// are the matrix's rounded to float once; the benchmarks run them in double as well (the timings do not
// depend on the digits, and every check compares with the host product of the same values).
void write_compact(const BlockMatrix &A, const std::string &path)
{
  std::ofstream f(path, std::ios::binary);
  const int32_t head[4] = {0x314d4242, A.bs, A.mbs, (int32_t)A.col.size()};
  f.write((const char *)head, sizeof head);
  f.write((const char *)A.ptr.data(), sizeof(int) * A.ptr.size());
  f.write((const char *)A.col.data(), sizeof(int) * A.col.size());
  std::vector<float> v(A.val.begin(), A.val.end());
  f.write((const char *)v.data(), sizeof(float) * v.size());
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    std::exit(2);
  }
}
BlockMatrix read_compact(const std::string &path)
{
  std::ifstream f(path, std::ios::binary);
  int32_t       head[4] = {0, 0, 0, 0};
  f.read((char *)head, sizeof head);
  if (!f || head[0] != 0x314d4242 || head[1] < 1 || head[1] > 8 || head[2] < 1 || head[3] < 0) {
    std::fprintf(stderr, "%s: not a compact block matrix (BBM1)\n", path.c_str());
    std::exit(2);
  }
  BlockMatrix A;
  A.name = path.substr(path.find_last_of('/') + 1);
  A.bs   = head[1];
  A.mbs  = head[2];
  A.ptr.resize((size_t)A.mbs + 1);
  A.col.resize(head[3]);
  std::vector<float> v((size_t)head[3] * A.bs * A.bs);
  f.read((char *)A.ptr.data(), sizeof(int) * A.ptr.size());
  f.read((char *)A.col.data(), sizeof(int) * A.col.size());
  f.read((char *)v.data(), sizeof(float) * v.size());
  bool ok = f && A.ptr[0] == 0 && A.ptr[A.mbs] == head[3];
  for (int r = 0; ok && r < A.mbs; r++) ok = A.ptr[r] <= A.ptr[r + 1];
  for (size_t k = 0; ok && k < A.col.size(); k++) ok = A.col[k] >= 0 && A.col[k] < A.mbs;
  if (!ok) {
    std::fprintf(stderr, "%s: truncated or inconsistent compact block matrix\n", path.c_str());
    std::exit(2);
  }
  A.val.assign(v.begin(), v.end());
  return A;
}
// A matrix file: compact (.bbm) or PETSc binary (anything else).
BlockMatrix read_matrix(const std::string &path, int bs)
{
  if (path.size() > 4 && path.compare(path.size() - 4, 4, ".bbm") == 0) return read_compact(path);
  return read_petsc_binary(path, bs);
}

} // namespace gpu_bench
