// Slab Gauss-Seidel: a symmetric block Gauss-Seidel smoother for multigrid levels whose couplings are
// short-ranged in the row numbering (the cloth's grid levels), with 8 rows relaxed side by side.
//
// Why: a Gauss-Seidel sweep in the natural order is a chain, row r waits for row r - 1 (its neighbour),
// so binbcsr's MatSOR walks one lane at a time and its symmetric sweep on the cloth's fine level cost
// 5.5-7 products (docs/cloth.md). Here the block rows are cut into 8 slabs of S = ceil(n / 8) rows and
// lane l of step j relaxes row l S + j. When no row is coupled to a row S or more away, the 8 rows of
// one step are not coupled to each other, so relaxing them together is exactly a Gauss-Seidel sweep in
// the order (j, l): every row reads the newest value of every neighbour, as the sequential sweep would,
// and the 8 relaxations are independent (no chain between them). A symmetric sweep is the forward
// sweep over j followed by the backward one, so the V-cycle stays symmetric for CG.
//
// The level's 3x3 blocks come as a list of (row, column, source block, transposed) entries, refilled
// from the source values in place: the driver's COO blocks on the fine level, SeqBAIJ arrays on the
// coarse ones. The level must be symmetric (a Galerkin product of a symmetric operator is): each row
// keeps only its blocks toward rows of later steps, the others are their transposes, pushed from the rows
// that keep them (slab_gs.cpp), so a sweep reads half the bytes. Off-diagonal blocks are stored in single
// precision (the smoother only damps the error, see smoother_copy.h); the diagonal blocks are inverted
// in double.
#pragma once
#include <petscksp.h>

#include <memory>
#include <string>
#include <vector>

struct SlabGS {
  static constexpr int lanes = 8;
  int                  n     = 0; // block rows
  int                  steps = 0; // S = ceil(n / lanes): rows per slab
  // entries of the level: block row, block column, index of the source block, source block transposed
  struct Entry {
    int  row, col;
    long source;
    bool transposed;
  };
  // the refill's copies: source block -> val (off-diagonal) or dl (diagonal) offset of its entry 0,
  // the block read row by row or transposed (flip: a column-major or a transposed source, not both)
  struct Copy {
    long source, dest;
    bool flip;
  };
  std::vector<Copy> copies, diagonal_copies;
  // The sweeps keep x and b lane by lane: component i of row r at lane_index(r) + i * lanes, with
  // lane_index(r) = lanes + (r % S) * 3 * lanes + r / S (one padding register before and after). Step j's
  // rows are then one register per component, and a slot group whose lanes all read the neighbour at
  // the same offset (a grid level away from its edges) reads x with plain loads.
  std::vector<int> step_start;           // slot groups of step j: step_start[j] .. step_start[j + 1]
  std::vector<int> xidx;                 // [group * lanes + lane] lane_index of the lane's column
  std::vector<int> base;                 // [group] xidx - lane where that is one number for the group's real
                                         // lanes (plain loads), -1: the group gathers
  std::vector<unsigned char> real;       // [group] the lanes with a block in the group (bit per lane)
  std::vector<float>         val;        // [group * 9 lanes + entry * lanes + lane], entries row-major
  std::vector<double>        dinv;       // [step * 9 lanes + entry * lanes + lane]: the inverses
  std::vector<double>        dl;         // the diagonal blocks (repeats summed), laid out as dinv
  std::vector<double>        xl, bl, rl; // x, b and a residual lane by lane during an application
  std::vector<double>        ll;         // the lower part L x of the rows, lane by lane (see slab_gs.cpp)
  // The Vec (id and state) bl and xl were last converted from or to, for the PETSc-facing applications:
  // in a V-cycle the residual reads the b and x the pre-smoothing just left, and the post-smoothing the
  // same b, so those conversions are skipped while the Vec is unchanged (id 0: nothing held).
  struct Held {
    PetscObjectId    id    = 0;
    PetscObjectState state = 0;
  };
  Held held_b, held_x;
  // A rank's rows of a distributed level (SlabGSSetHalo): their blocks toward other ranks' rows, so that
  // a sweep from a guess moves the other ranks' part to the right-hand side, b - A_halo x_ghost (x_ghost
  // gathered from the level's Vec), and sweeps this rank's rows: block Jacobi between the ranks, as
  // SOR's local sweeps, with no residual product of the whole operator.
  struct HaloEntry {
    int  row, ghost; // this rank's block row, index into ghost_nodes
    long source;     // source block
    bool transposed;
  };
  bool                   distributed  = false;
  bool                   column_major = false; // the source blocks' layout (SlabGSBuild)
  std::vector<PetscInt>  ghost_nodes;          // their global block rows in the level's numbering
  std::vector<HaloEntry> halo;
  std::vector<double>    halo_val;     // 9 per halo entry, row-major
  std::shared_ptr<void>  halo_scatter; // the scatter of x's ghost entries and their Vec (slab_gs.cpp)
};

// Which object obj is and its state now (PetscObjectStateGet is PETSc's private API): a Held to compare.
PetscErrorCode SlabGSHeldOf(PetscObject obj, SlabGS::Held *held);

// Builds the layout for n block rows from entries (every off-diagonal block the row has, of a symmetric
// matrix; the diagonal ones possibly repeated: they are summed). Returns an empty string, or why the rows
// cannot be relaxed side by side (a coupling S or more rows away).
std::string SlabGSBuild(int n, std::vector<SlabGS::Entry> entries, bool column_major_source, SlabGS *gs);

// Makes gs a distributed level's (on every rank of it): halo, the blocks of its rows toward other ranks'
// rows (ghost_nodes: those rows' global block numbers in the level's Vec), refilled with the others.
void SlabGSSetHalo(SlabGS *gs, std::vector<SlabGS::HaloEntry> halo, std::vector<PetscInt> ghost_nodes);

// New values: blocks of 9 (row-major, or column-major when the layout says so) indexed by the entries'
// source. PETSC_ERR_MAT_LU_ZRPVT naming the block row for a singular diagonal block.
PetscErrorCode SlabGSRefill(SlabGS *gs, const PetscScalar *blocks);

// One forward (or backward) sweep of x over all rows with right-hand side b (3 n values each, row by
// row): the portable sweep (SlabGSSweep, the definition) and the best the CPU runs (SlabGSSweepBest:
// AVX-512 where it has it; the same sums, possibly contracted differently). gs's lane vectors are the
// work space.
void SlabGSSweep(SlabGS &gs, const double *b, double *x, bool forward);
void SlabGSSweepBest(SlabGS &gs, const double *b, double *x, bool forward);

// r = b - A x (row by row), in one pass over the layout as a sweep makes (best: the CPU's best body).
void SlabGSResidual(SlabGS &gs, const double *b, const double *x, double *r, bool best);
// The same as PCMG's residual for a level (PCMGSetResidual), A the level's operator with its SlabGS
// attached (SlabGSAttach: composed as "SlabGS"; gs must outlive that use of A). gs must hold every
// coupling of its rows: a whole level, or a rank's rows with their halo (then collective: x's ghosts).
PetscErrorCode SlabGSAttach(Mat A, SlabGS *gs);
PetscErrorCode SlabGSResidualMat(Mat A, Vec b, Vec x, Vec r);

// its symmetric sweeps of x from x (or from zero) with right-hand side b: the PCApplyRichardson of
// SlabGSSetPC with whole (collective on a distributed level: the ghosts' exchange).
PetscErrorCode SlabGSApplySweeps(SlabGS *gs, Vec b, Vec x, PetscInt its, PetscBool zero_guess);

// Makes pc a PCSHELL for the smoother of a PCMG level (KSPRICHARDSON, one application). whole: gs holds every
// coupling of the operator's rows (in its layout, or toward other ranks in its halo), and the sweeps run from
// the smoother's guess (PCApplyRichardson, no residual product). Else (a rank's rows of a distributed
// operator, their couplings to other ranks left out) the PC applies one symmetric sweep from zero to the
// residual KSPRICHARDSON forms with the whole operator: x + M^-1 (b - A x), the same as sweeping the rank's
// rows from x with the other ranks' part moved to the right-hand side (SOR's local sweeps). gs must outlive
// pc.
PetscErrorCode SlabGSSetPC(PC pc, SlabGS *gs, PetscBool whole);
