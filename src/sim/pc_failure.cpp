#include "sim/pc_failure.h"

#include <petsc/private/pcimpl.h> // whether a PC is set up (its blocks exist)
#include "petsc_compat.h"         // PCGetFailedReasonRank

#include <cstring>

namespace {

// This rank's first recorded failure in pc, its inner PCs first: for PCMG and the types built on it
// (PCGAMG) its levels' smoothers (finest first) and coarse solve, for PCBJACOBI and PCASM this rank's
// blocks. where: how to reach pc from the top ("" for the top).
PetscErrorCode LocalFailure(PC pc, const std::string &where, std::string *what)
{
  PCFailedReason reason;
  PetscBool      mg, blocks;

  PetscFunctionBegin;
  what->clear();
  PetscCall(PetscObjectTypeCompareAny((PetscObject)pc, &mg, PCMG, PCGAMG, ""));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)pc, &blocks, PCBJACOBI, PCASM, ""));
  const std::string in = where.empty() ? "" : where + ", ";
  if (mg) {
    PetscInt levels = 0;
    PetscCall(PCMGGetLevels(pc, &levels));
    for (PetscInt l = levels - 1; l >= 0 && what->empty(); --l) {
      KSP smoother = nullptr;
      PC  spc;
      if (l > 0) PetscCall(PCMGGetSmoother(pc, l, &smoother));
      else PetscCall(PCMGGetCoarseSolve(pc, &smoother));
      if (!smoother) continue;
      PetscCall(KSPGetPC(smoother, &spc));
      PetscCall(
        LocalFailure(spc, in + (l > 0 ? "level " + std::to_string(l) + " smoother" : "coarse solve"), what));
    }
  } else if (blocks && pc->setupcalled) { // the blocks exist once the PC is set up
    PetscInt  n = 0, first = 0;
    KSP      *sub = nullptr;
    PetscBool bjacobi;
    PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCBJACOBI, &bjacobi));
    if (bjacobi) PetscCall(PCBJacobiGetSubKSP(pc, &n, &first, &sub));
    else PetscCall(PCASMGetSubKSP(pc, &n, &first, &sub));
    for (PetscInt b = 0; b < n && what->empty(); ++b) {
      PC bpc;
      PetscCall(KSPGetPC(sub[b], &bpc));
      PetscCall(LocalFailure(bpc, in + "block " + std::to_string(first + b), what));
    }
  }
  if (!what->empty()) PetscFunctionReturn(0);
  PetscCall(PCGetFailedReasonRank(pc, &reason));
  if (reason != PC_NOERROR)
    *what = (where.empty() ? std::string("preconditioner") : where) + ": " + PCFailedReasons[reason];
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode DescribePCFailure(KSP ksp, std::string *what)
{
  PC          pc;
  MPI_Comm    comm;
  PetscMPIInt rank, size, first;
  std::string local;
  char        buf[160] = "";

  PetscFunctionBegin;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectGetComm((PetscObject)ksp, &comm));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(LocalFailure(pc, "", &local));
  const PetscMPIInt mine = local.empty() ? size : rank;
  PetscCallMPI(MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm));
  what->clear();
  if (first == size) PetscFunctionReturn(0);
  if (rank == first) std::strncpy(buf, local.c_str(), sizeof buf - 1);
  PetscCallMPI(MPI_Bcast(buf, (int)sizeof buf, MPI_CHAR, first, comm));
  *what = buf;
  if (size > 1) *what += " on rank " + std::to_string(first);
  PetscFunctionReturn(0);
}
