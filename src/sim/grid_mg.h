// Geometric multigrid (PCMG) for a square n x n grid of nodes with 3 unknowns each (the cloth), whatever
// the fine operator's Mat type: the driver knows the grid, PETSc does not.
// The fine operator must be symmetric (CG's): the block Galerkin products sum only the coarse blocks on
// and above the diagonal.
//
// Levels: every coarsening keeps every other node per side (n -> n / 2 + 1), until a level has at most
// -grid_mg_coarse_nodes nodes (default 150; the 160 x 160 cloth gets 160, 81, 41, 21, 11). Interpolation:
// bilinear, the same weights for each of the 3 components, one matrix per level, built once (the grid does
// not change; MAIJ with the block Galerkin products, AIJ for PCMG's). Rows of fixed (Dirichlet)
// fine nodes are zero: their equations hold only the mass, the smoother solves them exactly, and a coarse
// correction must not move them. Coarse operators: Galerkin, P^T A P for every new set of values, by default
// from the driver's COO blocks (block_galerkin.h): on one rank SeqBAIJ coarse levels, on more each rank's
// share from its own rows summed by COO into AIJ levels (grid_mg_aij.h); with -grid_mg_galerkin pcmg by
// PCMG's MatPtAP (AIJ) at its set-up. Smoothers: -grid_mg_levels_[N_]* (default one symmetric Gauss-Seidel
// sweep), coarse solve: -grid_mg_coarse_* (default LU, redundant on more ranks); GAMG's -mg_levels_* do not
// reach them.
// -grid_mg_smoother slab (the default; sor: the SOR above): each level whose couplings allow it smooths with
// slab Gauss-Seidel (slab_gs.h), the same symmetric block Gauss-Seidel sweep with 8 rows relaxed side by
// side, the others keep SOR. On more ranks every level but the coarsest does, each rank on its own rows
// (block Jacobi between the ranks, as SOR's local sweeps) with their couplings to other ranks as the slabs'
// halo: the sweeps run from the smoother's guess and the levels' residuals are taken in the slabs' layout.
// -grid_mg_smoother_precision single (one rank with the block Galerkin products; ignored otherwise): the
// smoothers sweep single-precision binbcsr copies of the level operators (the fine one duplicated, the coarse
// BAIJ ones in upper-triangle storage) and the V-cycle's residuals are taken on them too, while
// interpolation, the Galerkin products and the outer Krylov method stay on the operators themselves. The
// V-cycle only has to reduce the error, so its rounding does not reach the solution; the sweeps read a half
// (fine) or a quarter (coarse) of the bytes.
//
// On P ranks the fine rows are those of the solver's numbering (new_of_old, rows row_offsets[r] ..
// row_offsets[r + 1] on rank r); each coarse node belongs to the rank owning the fine node nearest to it.
#pragma once
#include "sim/block_galerkin.h"
#include "sim/slab_gs.h"

#include <petscksp.h>
#include <vector>

struct GridMG {
  std::vector<PetscInt> sides;                // nodes per side, finest first
  bool                  own_galerkin = false; // coarse operators from block_galerkin.h, else PCMG's MatPtAP
  // own_galerkin on more ranks: each rank's share of the first product from its own blocks (galerkin[0],
  // all the level's nodes), summed into the AIJ aij_levels[0] by COO; the coarser levels by MatPtAP
  bool             distributed = false;
  std::vector<Mat> aij_levels; // finest coarse level first
  struct DistributedLevel {    // coarse level l + 1 of the distributed products (dist_levels[l])
    std::vector<int>                      num, offsets; // its nodes' solver numbers, the ranks' ranges
    PetscInt                              side = 0;
    std::vector<std::vector<BlockWeight>> weights; // the interpolation to level l from it (physics numbering)
    // as the source of the next product: this rank's blocks of the level, gathered from the AIJ values
    std::vector<PetscInt>    gather;
    PetscInt                 diagonal_count = 0;
    std::vector<PetscScalar> blocks;
    SlabGS::Held             held; // the AIJ level (and its values) blocks holds: its slabs take them too
  };
  std::vector<DistributedLevel> dist_levels;
  std::vector<BlockGalerkin>    galerkin; // level l + 1 from level l
  PC                            pc = nullptr;
  // -grid_mg_smoother_precision single: every level smooths on a single-precision binbcsr copy of its
  // operator (upper triangle on the coarse levels) and takes its residual there; the outer CG keeps the
  // operators
  bool             single_smoothers = false;
  std::vector<Mat> smoother_mats; // per PCMG level (0 unused): the copies, made at the first refill
  // -grid_mg_smoother slab: per PCMG level (0 unused), the slab Gauss-Seidel smoother (slab_gs.h) where
  // its couplings allow it (on more ranks this rank's rows, with their halo); slab_used[l] says whether it
  // does (decided at the set-up for the fine level, at the first refill or the smoother's first set-up
  // for the coarse ones)
  enum SlabUse : char {
    kUndecided,
    kSlab,
    kSor
  };
  bool                 smoother_slab = false;
  std::vector<SlabGS>  slabs;
  std::vector<SlabUse> slab_used;
  // On more ranks (and with PCMG's products) the coarse levels' operators are AIJ: their smoothers are
  // PCSHELLs whose own set-up takes the level's 3x3 blocks from this rank's rows of the operator
  // (slabs[level] then sweeps them as on the fine level, the blocks toward other ranks as the halo), or
  // keeps SOR where the ranks cannot all sweep slabs. One per PCMG level (0 and the fine one unused).
  struct AijSlab {
    GridMG  *mg    = nullptr;
    PetscInt level = 0;
    // this rank's blocks of the level (grid_mg_aij.h's GridMGAijBlocks) and their values for SlabGSRefill
    std::vector<PetscInt>    gather;
    PetscInt                 diagonal_count = 0;
    std::vector<PetscScalar> blocks;
    SlabGS::Held             held;          // the operator (and its state) the slabs hold
    PC                       sor = nullptr; // the level keeps SOR: this PC does it
  };
  std::vector<AijSlab> aij_slabs;
};

// ksp's PC must be PCMG (-pc_type mg). fixed: n * n flags (row-major, physics numbering). coo_row, coo_col:
// the driver's COO list of 3x3 blocks (physics numbering; coo_mirrored: blocks off the diagonal stand for
// their transposes too, but with offrank_full not those coupling two ranks: each rank lists its own rows'
// blocks toward other ranks whole, ReplicatedSolverStoresBlock), whose values GridMGRefill takes.
PetscErrorCode GridMGSetUp(KSP ksp, PetscInt n, const std::vector<char> &fixed,
                           const std::vector<int> &new_of_old, const std::vector<int> &row_offsets,
                           const std::vector<int> &coo_row, const std::vector<int> &coo_col,
                           PetscBool coo_mirrored, PetscBool offrank_full, GridMG *mg);
// The coarse operators for new fine values (9 per COO block, row-major), after the fine matrix's refill.
PetscErrorCode GridMGRefill(GridMG *mg, const PetscScalar *coo_values);
PetscErrorCode GridMGDestroy(GridMG *mg);
