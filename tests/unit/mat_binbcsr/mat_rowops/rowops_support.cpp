#include "rowops_support.hpp"

#include <algorithm>
#include <map>

namespace rowops {

std::vector<Config> configs()
{
  std::vector<Config> v;
  for (PetscInt bs : {1, 3})
    for (bool sym : {false, true})
      for (MatBinBCSRPrecision prec : {MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE})
        for (PetscInt bw : {0, 5}) {
          Config c;
          c.holes = bw == 0;
          c.bs    = bs;
          c.sym   = sym;
          c.prec  = prec;
          c.bw    = bw;
          v.push_back(c);
        }
  for (bool sym : {false, true}) { // the generic block size path
    Config c;
    c.bs   = 2;
    c.sym  = sym;
    c.prec = sym ? MAT_BINBCSR_PRECISION_SINGLE : MAT_BINBCSR_PRECISION_DOUBLE;
    v.push_back(c);
  }
  return v;
}

bool block_present(const Config &c, PetscInt I, PetscInt J)
{
  const unsigned lo = (unsigned)std::min(I, J), hi = (unsigned)std::max(I, J);
  if (c.holes && (I % 7 == 5 || J % 7 == 5)) return false;
  if (I == J || (!c.holes && lo == 1)) return true; /* without holes block row (and column) 1 is dense */
  bool present = hi - lo == 1 || hash3(lo, hi, 11) % 100 < 25;
  if (c.drop && present && hash3(lo, hi, 12) % 3 == 0) present = false;
  if (c.extra && !present && hash3(lo, hi, 13) % 100 < 10) present = true;
  return present;
}

static double scale_of(PetscInt I) { return std::pow(10.0, (double)(hash3((unsigned)I, 0, 21) % 5) - 2.0); }

double entry(const Config &c, PetscInt i, PetscInt j)
{
  const unsigned a = c.sym ? (unsigned)std::min(i, j) : (unsigned)i,
                 b = c.sym ? (unsigned)std::max(i, j) : (unsigned)j;
  const unsigned h = hash3(a, b, 30 + c.value_seed);
  double         u = h % 10 == 0 ? 0.0 : ((double)(h % 20001) - 10000.0) / 10000.0;
  if (c.ties) u = (double)(h % 3) - 1.0;
  if (i == j) u += 2.0; // mostly positive diagonal
  /* rows of one sign, where the implicit zeros decide MatGetRowMax/Min (the row's block for full storage,
     the pair's first block for symmetric storage) */
  const PetscInt lo = (c.sym ? std::min(i, j) : i) / c.bs;
  if (lo % 5 == 1) u = -std::fabs(u) - 0.1;
  if (lo % 5 == 3) u = std::fabs(u) + 0.1;
  const double v =
    u * (scale_of(std::min(i, j) / c.bs) * scale_of(std::max(i, j) / c.bs)); // bitwise symmetric
  return c.prec == MAT_BINBCSR_PRECISION_SINGLE || c.float_values ? (double)(float)v : v;
}

PetscErrorCode make(const Config &c, const char *type, Mat *A)
{
  const PetscInt M = c.mbs() * c.bs;
  PetscInt       rstart, rend;
  PetscBool      isbin;

  PetscFunctionBeginUser;
  PetscCall(MatCreate(PETSC_COMM_WORLD, A));
  PetscCall(MatSetSizes(*A, PETSC_DECIDE, PETSC_DECIDE, M, M));
  PetscCall(MatSetBlockSize(*A, c.bs));
  PetscCall(MatSetType(*A, type));
  PetscCall(PetscStrcmp(type, MATBINBCSR, &isbin));
  if (isbin) {
    PetscCall(MatBinBCSRSetPrecision(*A, c.prec));
    PetscCall(MatBinBCSRSetSymmetricStorage(*A, c.sym && !c.full_storage ? PETSC_TRUE : PETSC_FALSE));
    if (c.bw) PetscCall(MatBinBCSRSetBinWidth(*A, c.bw));
  }
  PetscCall(MatSetUp(*A));
  if (!isbin) PetscCall(MatSetOption(*A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
  PetscCall(MatGetOwnershipRange(*A, &rstart, &rend));
  std::vector<PetscInt>    cols;
  std::vector<PetscScalar> vals;
  for (PetscInt i = rstart; i < rend; i++) {
    cols.clear();
    vals.clear();
    for (PetscInt J = 0; J < c.mbs(); J++) {
      if (!block_present(c, i / c.bs, J)) continue;
      for (PetscInt j = J * c.bs; j < (J + 1) * c.bs; j++) {
        cols.push_back(j);
        vals.push_back(entry(c, i, j));
      }
    }
    PetscCall(MatSetValues(*A, 1, &i, (PetscInt)cols.size(), cols.data(), vals.data(), INSERT_VALUES));
  }
  PetscCall(MatAssemblyBegin(*A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*A, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}

double row_error(Mat got, Mat want)
{
  PetscInt rstart, rend;
  double   worst = 0, all;
  REQUIRE(MatGetOwnershipRange(want, &rstart, &rend) == 0);
  for (PetscInt i = rstart; i < rend; i++) {
    std::map<PetscInt, double> diff;
    double                     scale = 0;
    PetscInt                   n;
    const PetscInt            *cols;
    const PetscScalar         *vals;
    REQUIRE(MatGetRow(want, i, &n, &cols, &vals) == 0);
    for (PetscInt k = 0; k < n; k++) {
      diff[cols[k]] -= vals[k];
      scale += std::fabs(vals[k]);
    }
    REQUIRE(MatRestoreRow(want, i, &n, &cols, &vals) == 0);
    REQUIRE(MatGetRow(got, i, &n, &cols, &vals) == 0);
    for (PetscInt k = 0; k < n; k++) diff[cols[k]] += vals[k];
    REQUIRE(MatRestoreRow(got, i, &n, &cols, &vals) == 0);
    for (const auto &d : diff) worst = std::max(worst, std::fabs(d.second) / (scale > 0 ? scale : 1.0));
  }
  REQUIRE(MPI_Allreduce(&worst, &all, 1, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD) == 0);
  return all;
}

PetscErrorCode make_vec(Mat A, bool left, unsigned seed, Vec *v)
{
  PetscInt     rstart, rend;
  PetscScalar *a;

  PetscFunctionBeginUser;
  PetscCall(MatCreateVecs(A, left ? nullptr : v, left ? v : nullptr));
  PetscCall(VecGetOwnershipRange(*v, &rstart, &rend));
  PetscCall(VecGetArray(*v, &a));
  for (PetscInt i = rstart; i < rend; i++) {
    const unsigned h = hash3((unsigned)i, seed, 41);
    a[i - rstart]    = (h % 2 ? -1.0 : 1.0) * (0.5 + 1.5 * (double)(h % 1000) / 1000.0) *
                    std::pow(10.0, (double)(h % 3) - 1.0);
  }
  PetscCall(VecRestoreArray(*v, &a));
  PetscFunctionReturn(0);
}

} // namespace rowops
