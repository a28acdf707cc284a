// A small FEM-like problem for the MPI tests: a grid of hexahedra with 3 unknowns per node, element
// matrices (8 I - 1 1^T) (x) S_e + mass, assembled in parallel by any rank for any element (so rows of
// other ranks go through the stash / the COO exchange), and the same matrix assembled serially on
// every rank as the reference. Node numbering can be shuffled (a ghost-heavy, deliberately bad
// partition) and rank 0 can be given no rows.
#pragma once
#include <petscbinbcsr.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

namespace mpitest {

struct FemProblem {
  int              nx, ny, nz;
  std::vector<int> node_of;  // grid node -> matrix node (a permutation)
  std::vector<int> elements; // 8 grid nodes per element

  FemProblem(int nx_, int ny_, int nz_, bool shuffle) : nx(nx_), ny(ny_), nz(nz_)
  {
    node_of.resize(nodes());
    std::iota(node_of.begin(), node_of.end(), 0);
    if (shuffle) std::shuffle(node_of.begin(), node_of.end(), std::mt19937(11));
    auto id = [&](int i, int j, int k) { return i + nx * (j + ny * k); };
    for (int k = 0; k + 1 < nz; ++k)
      for (int j = 0; j + 1 < ny; ++j)
        for (int i = 0; i + 1 < nx; ++i)
          for (int c = 0; c < 8; ++c)
            elements.push_back(id(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)));
  }
  int      nodes() const { return nx * ny * nz; }
  int      element_count() const { return static_cast<int>(elements.size() / 8); }
  PetscInt rows() const { return 3 * nodes(); }

  // 24x24 element matrix, row-major, rows ordered (node a, component p).
  std::vector<PetscScalar> element_matrix(int e) const
  {
    const double             s       = 0.01 * (e % 7);
    const double             S[3][3] = {{2 + s, 0.1, 0}, {0.1, 2, 0.2 + s}, {0, 0.2 + s, 2.5}};
    std::vector<PetscScalar> K(24 * 24);
    for (int a = 0; a < 8; ++a)
      for (int p = 0; p < 3; ++p)
        for (int b = 0; b < 8; ++b)
          for (int q = 0; q < 3; ++q)
            K[(3 * a + p) * 24 + 3 * b + q] =
              ((a == b ? 8.0 : 0.0) - 1.0) * S[p][q] + (a == b && p == q ? 0.5 : 0.0);
    return K;
  }
  // Block (node) indices of element e in the matrix numbering.
  std::vector<PetscInt> element_blocks(int e) const
  {
    std::vector<PetscInt> blk(8);
    for (int a = 0; a < 8; ++a) blk[a] = node_of[elements[8 * e + a]];
    return blk;
  }
  // Scalar indices of element e.
  std::vector<PetscInt> element_rows(int e) const
  {
    std::vector<PetscInt> r(24);
    for (int a = 0; a < 8; ++a)
      for (int p = 0; p < 3; ++p) r[3 * a + p] = 3 * node_of[elements[8 * e + a]] + p;
    return r;
  }
};

// Local row count (multiple of 3) for this rank: nodes split evenly, or rank 0 given none.
inline PetscInt local_rows(const FemProblem &fem, MPI_Comm comm, bool empty_rank0)
{
  PetscMPIInt rank, size;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  int parts = size, me = rank;
  if (empty_rank0 && size > 1) {
    if (rank == 0) return 0;
    parts = size - 1;
    me    = rank - 1;
  }
  const int n = fem.nodes();
  return 3 * (n / parts + (me < n % parts ? 1 : 0));
}

// This rank's share of a COO list of the whole problem: elements dealt round-robin over PETSC_COMM_WORLD
// (so most entries belong to other ranks' rows), each element's 24 x 24 entries row by row.
inline void rank_coo_entries(const FemProblem &fem, std::vector<PetscInt> &ci, std::vector<PetscInt> &cj)
{
  PetscMPIInt rank, size;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  for (int e = rank; e < fem.element_count(); e += size) {
    const auto r = fem.element_rows(e);
    for (int a = 0; a < 24; ++a)
      for (int b = 0; b < 24; ++b) {
        ci.push_back(r[a]);
        cj.push_back(r[b]);
      }
  }
}

// The values of rank_coo_entries' list, element e's matrix scaled by weight(e).
template <class Weight> std::vector<PetscScalar> rank_element_values(const FemProblem &fem, Weight weight)
{
  PetscMPIInt rank, size;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  std::vector<PetscScalar> cv;
  for (int e = rank; e < fem.element_count(); e += size) {
    const double w = weight(e);
    for (PetscScalar k : fem.element_matrix(e)) cv.push_back(w * k);
  }
  return cv;
}

// True on every rank iff ok on every rank (so that all ranks pass or fail a check together).
inline bool all_ranks(bool ok, MPI_Comm comm = PETSC_COMM_WORLD)
{
  int l = ok ? 1 : 0, g = 0;
  MPI_Allreduce(&l, &g, 1, MPI_INT, MPI_LAND, comm);
  return g != 0;
}

// max |S - T| / max |T|, S converted to T's type (1e300 if it cannot be).
inline double mat_rel_diff(Mat S, Mat T)
{
  Mat       C;
  MatType   type;
  PetscReal d = -1, t = 1;
  MatGetType(T, &type);
  if (MatConvert(S, type, MAT_INITIAL_MATRIX, &C)) return 1e300;
  MatAXPY(C, -1.0, T, DIFFERENT_NONZERO_PATTERN);
  MatNorm(C, NORM_MAX, &d);
  MatNorm(T, NORM_MAX, &t);
  MatDestroy(&C);
  return d / t;
}

// max |x - y| / max |y|
inline double vec_rel_diff(Vec x, Vec y)
{
  Vec       d;
  PetscReal nd = 0, ny = 1;
  VecDuplicate(x, &d);
  VecWAXPY(d, -1.0, x, y);
  VecNorm(d, NORM_INFINITY, &nd);
  VecNorm(y, NORM_INFINITY, &ny);
  VecDestroy(&d);
  return nd / ny;
}

} // namespace mpitest
