// reorder_bench: what a locality (bandwidth) reordering buys MatMult on one rank, and what a METIS
// partition buys on several. The 27-point 3x3-block stencil (src/sim/stencil.h) on an n^3 grid
// is numbered four ways: natural (lexicographic), randomly shuffled (a mesh file from a generator with
// no locality), shuffled then reverse Cuthill-McKee, shuffled then METIS nested dissection
// (src/physics/partition.hpp), and MatMult is timed for each numbering and format in the same run.
// Under mpiexec (P ranks) the shuffled numbering is also partitioned by METIS into P contiguous parts
// (+ RCM inside each part) and the ghost count per rank is printed beside the time.
//
//   reorder_bench [-n 32] [-formats binbcsr,baij,aij] [-repeats 7] [-min_batch_ms 20]
#include <petscbinbcsr.h>
#include <petsc/private/matimpl.h>

#include "sim/bench_util.h"
#include "sim/stencil.h"
#include "physics/partition.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <random>
#include <string>
#include <vector>

namespace {

struct Ordering {
  std::string      name;
  std::vector<int> new_of_old; // grid node -> matrix block row
  std::vector<int> offsets;    // rank ranges (block rows), or empty: PETSc's default layout
  int              bandwidth = 0;
};

PetscErrorCode assemble(const StencilGrid &grid, const Ordering &ord, const char *type, Mat *A)
{
  PetscMPIInt rank, size;
  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  const PetscInt N = 3 * grid.nodes();
  PetscInt       m = PETSC_DECIDE;
  if (!ord.offsets.empty()) m = 3 * (ord.offsets[rank + 1] - ord.offsets[rank]);
  PetscCall(MatCreate(PETSC_COMM_WORLD, A));
  PetscCall(MatSetSizes(*A, m, m, N, N));
  PetscCall(MatSetBlockSize(*A, 3));
  PetscCall(MatSetType(*A, type));
  PetscCall(MatSetFromOptions(*A));
  PetscCall(PetscLayoutSetUp((*A)->rmap));
  PetscInt rstart, rend;
  PetscCall(MatGetOwnershipRange(*A, &rstart, &rend));
  std::vector<int> old_of_new(ord.new_of_old.size());
  for (std::size_t v = 0; v < old_of_new.size(); ++v) old_of_new[ord.new_of_old[v]] = static_cast<int>(v);
  // The exact block counts of the diagonal and off-diagonal parts: a fixed 27 for both was refused
  // ("nnz cannot be greater than block row length") where a rank holds fewer than 27 block columns.
  const PetscInt        brows = (rend - rstart) / 3;
  std::vector<PetscInt> dnnz(brows, 0), onnz(brows, 0);
  for (PetscInt row = rstart / 3; row < rend / 3; ++row) {
    PetscInt    ncols, cols[27];
    PetscScalar vals[27 * 9];
    StencilBlockRow(grid, old_of_new[row], &ncols, cols, vals);
    for (PetscInt k = 0; k < ncols; ++k) {
      const PetscInt c = ord.new_of_old[cols[k]];
      ++(c >= rstart / 3 && c < rend / 3 ? dnnz : onnz)[row - rstart / 3];
    }
  }
  PetscCall(MatXAIJSetPreallocation(*A, 3, dnnz.data(), onnz.data(), nullptr, nullptr));
  // each rank inserts its own block rows: no stash traffic in the timing setup
  for (PetscInt row = rstart / 3; row < rend / 3; ++row) {
    PetscInt    ncols, cols[27];
    PetscScalar vals[27 * 9];
    StencilBlockRow(grid, old_of_new[row], &ncols, cols, vals);
    for (PetscInt k = 0; k < ncols; ++k) cols[k] = ord.new_of_old[cols[k]];
    PetscCall(MatSetValuesBlocked(*A, 1, &row, ncols, cols, vals, INSERT_VALUES));
  }
  PetscCall(MatAssemblyBegin(*A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*A, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}

PetscErrorCode time_mult(Mat A, PetscInt repeats, PetscReal min_batch_ms, double *best_ms)
{
  Vec x, y;
  PetscFunctionBeginUser;
  PetscCall(MatCreateVecs(A, &x, &y));
  PetscCall(VecSetRandom(x, nullptr));
  PetscCall(MatMult(A, x, y));
  int batch = 1;
  for (;;) { // batch long enough to time
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    double t0 = MPI_Wtime();
    for (int k = 0; k < batch; ++k) PetscCall(MatMult(A, x, y));
    double t = MPI_Wtime() - t0;
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &t, 1, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD));
    if (t * 1e3 >= min_batch_ms || batch > 1 << 20) break;
    batch *= 2;
  }
  *best_ms = 1e300;
  for (PetscInt r = 0; r < repeats; ++r) {
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    double t0 = MPI_Wtime();
    for (int k = 0; k < batch; ++k) PetscCall(MatMult(A, x, y));
    double t = MPI_Wtime() - t0;
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &t, 1, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD));
    *best_ms = std::min(*best_ms, 1e3 * t / batch);
  }
  PetscCall(VecDestroy(&x));
  PetscCall(VecDestroy(&y));
  PetscFunctionReturn(0);
}

// Largest number of ghost block columns over the ranks: block columns outside the rank's range that
// its rows touch.
PetscErrorCode max_ghosts(const StencilGrid &grid, const Ordering &ord, PetscInt rstart, PetscInt rend,
                          PetscInt *ghosts)
{
  PetscFunctionBeginUser;
  std::vector<int> old_of_new(ord.new_of_old.size());
  for (std::size_t v = 0; v < old_of_new.size(); ++v) old_of_new[ord.new_of_old[v]] = static_cast<int>(v);
  std::vector<PetscInt> g;
  for (PetscInt row = rstart; row < rend; ++row) {
    PetscInt    ncols, cols[27];
    PetscScalar vals[27 * 9];
    StencilBlockRow(grid, old_of_new[row], &ncols, cols, vals);
    for (PetscInt k = 0; k < ncols; ++k) {
      const PetscInt c = ord.new_of_old[cols[k]];
      if (c < rstart || c >= rend) g.push_back(c);
    }
  }
  std::sort(g.begin(), g.end());
  PetscInt local = static_cast<PetscInt>(std::unique(g.begin(), g.end()) - g.begin());
  PetscCallMPI(MPI_Allreduce(&local, ghosts, 1, MPIU_INT, MPI_MAX, PETSC_COMM_WORLD));
  PetscFunctionReturn(0);
}

} // namespace

int main(int argc, char **argv)
{
  PetscInt    n = 32, repeats = 7;
  PetscReal   min_batch_ms = 20;
  char        formats[256] = "binbcsr,baij,aij";
  PetscMPIInt size;

  PetscCall(PetscInitialize(
    &argc, &argv, nullptr,
    "reorder_bench: MatMult time under natural, shuffled, RCM and nested-dissection numberings"));
  PetscCall(PetscBinBCSRRegisterAll());
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-n", &n, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-repeats", &repeats, nullptr));
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-min_batch_ms", &min_batch_ms, nullptr));
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-formats", formats, sizeof formats, nullptr));
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  /* -n -1 ended in an uncaught std::invalid_argument from the mesh graph, -n 0 timed 0 rows; the bound
     is CreateStencilMatrix's, before n^3 is formed */
  PetscCheck(n >= 1, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-n must be >= 1 (nodes a side), not %" PetscInt_FMT, n);
  PetscCheck(243.0 * n * n * n <= (double)PETSC_MAX_INT, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-n %" PetscInt_FMT ": the stencil's %.3g entries exceed PETSc's index range", n,
             243.0 * n * n * n);
  /* -repeats 0 printed the unset minimum (1e300, 300 digits); a NaN -min_batch_ms never ended a batch
     (the doubling ran to 2^20 products), 0 and negatives timed single products */
  PetscCheck(repeats >= 1, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-repeats must be >= 1, not %" PetscInt_FMT, repeats);
  PetscCheck(min_batch_ms > 0 && std::isfinite((double)min_batch_ms), PETSC_COMM_WORLD,
             PETSC_ERR_ARG_OUTOFRANGE, "-min_batch_ms must be positive and finite, not %g",
             (double)min_batch_ms);
  std::vector<std::string> fmts;
  PetscCall(SplitOptionList(PETSC_COMM_WORLD, "-formats", formats, &fmts));

  StencilGrid grid;
  grid.nx = grid.ny = grid.nz = n;
  // the stencil couples the nodes of each hexahedral cell: build that mesh's graph
  std::vector<int> hexes;
  auto id = [&](PetscInt i, PetscInt j, PetscInt k) { return static_cast<int>(i + n * (j + n * k)); };
  for (PetscInt k = 0; k + 1 < n; ++k)
    for (PetscInt j = 0; j + 1 < n; ++j)
      for (PetscInt i = 0; i + 1 < n; ++i)
        for (int c = 0; c < 8; ++c) hexes.push_back(id(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)));
  const physics::AdjacencyGraph graph =
    physics::graph_from_elements(static_cast<int>(grid.nodes()), 8, hexes);

  std::vector<Ordering> orders;
  Ordering              natural{"natural", std::vector<int>(grid.nodes()), {}, 0};
  std::iota(natural.new_of_old.begin(), natural.new_of_old.end(), 0);
  orders.push_back(natural);
  Ordering shuffled{"shuffled", natural.new_of_old, {}, 0};
  std::shuffle(shuffled.new_of_old.begin(), shuffled.new_of_old.end(), std::mt19937(5));
  orders.push_back(shuffled);
  // reorder the shuffled mesh, as a user with a badly numbered mesh file would
  physics::Renumbering sh;
  sh.new_of_old = shuffled.new_of_old;
  sh.old_of_new.resize(sh.new_of_old.size());
  for (std::size_t v = 0; v < sh.new_of_old.size(); ++v)
    sh.old_of_new[sh.new_of_old[v]] = static_cast<int>(v);
  const physics::AdjacencyGraph shuffled_graph = physics::renumber_graph(graph, sh);
  auto compose = [&](const physics::Renumbering &r, const char *name, std::vector<int> offsets) {
    Ordering o{name, std::vector<int>(grid.nodes()), offsets, 0};
    for (std::size_t v = 0; v < o.new_of_old.size(); ++v)
      o.new_of_old[v] = r.new_of_old[shuffled.new_of_old[v]];
    return o;
  };
  double t0 = MPI_Wtime();
  orders.push_back(
    compose(physics::reorder_for_locality(shuffled_graph, physics::LocalOrder::ReverseCuthillMcKee),
            "shuffled+RCM", {}));
  const double t_rcm = MPI_Wtime() - t0;
  t0                 = MPI_Wtime();
  orders.push_back(compose(
    physics::reorder_for_locality(shuffled_graph, physics::LocalOrder::NestedDissection), "shuffled+ND", {}));
  const double t_nd   = MPI_Wtime() - t0;
  double       t_part = 0;
  if (size > 1) {
    physics::PartitionOptions opt;
    opt.local_order = physics::LocalOrder::ReverseCuthillMcKee;
    t0              = MPI_Wtime();
    const auto part = physics::partition_graph(shuffled_graph, size, opt);
    t_part          = MPI_Wtime() - t0;
    orders.push_back(compose(part, "shuffled+METIS+RCM", part.part_offsets));
  }
  for (auto &o : orders) {
    physics::Renumbering r;
    r.new_of_old = o.new_of_old;
    r.old_of_new.resize(r.new_of_old.size());
    for (std::size_t v = 0; v < r.new_of_old.size(); ++v) r.old_of_new[r.new_of_old[v]] = static_cast<int>(v);
    o.bandwidth = physics::graph_bandwidth(physics::renumber_graph(graph, r));
  }

  PetscCall(PetscPrintf(PETSC_COMM_WORLD,
                        "reorder_bench: 27-point 3x3-block stencil, %" PetscInt_FMT "^3 nodes (%" PetscInt_FMT
                        " rows), %d rank(s)\n",
                        n, 3 * grid.nodes(), size));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "reordering cost: RCM %.3f s, nested dissection %.3f s%s", t_rcm,
                        t_nd, size > 1 ? "" : "\n"));
  if (size > 1)
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, ", METIS %d-way partition + RCM %.3f s\n", size, t_part));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD,
                        "MatMult ms: min over %" PetscInt_FMT " rounds of the slowest rank's batch average\n",
                        repeats));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "%-20s %10s %10s", "numbering", "bandwidth", "ghosts"));
  for (const auto &f : fmts) PetscCall(PetscPrintf(PETSC_COMM_WORLD, " %12s", f.c_str()));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "\n"));
  for (const auto &o : orders) {
    PetscInt            ghosts = 0;
    std::vector<double> ms;
    for (const auto &f : fmts) {
      Mat    A;
      double best;
      PetscCall(assemble(grid, o, f.c_str(), &A));
      PetscCall(time_mult(A, repeats, min_batch_ms, &best));
      if (ms.empty()) {
        PetscInt rstart, rend;
        PetscCall(MatGetOwnershipRange(A, &rstart, &rend));
        PetscCall(max_ghosts(grid, o, rstart / 3, rend / 3, &ghosts));
      }
      ms.push_back(best);
      PetscCall(MatDestroy(&A));
    }
    PetscCall(
      PetscPrintf(PETSC_COMM_WORLD, "%-20s %10d %10" PetscInt_FMT, o.name.c_str(), o.bandwidth, ghosts));
    for (double t : ms) PetscCall(PetscPrintf(PETSC_COMM_WORLD, " %12.3f", t));
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "\n"));
  }
  PetscCall(PetscFinalize());
  return 0;
}
