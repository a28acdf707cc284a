// The PETSc side of slab Gauss-Seidel (slab_gs.h): the level's Vecs in and out of the lane layout
// (skipped while a Vec is unchanged), the halo of a distributed level, the residual as the level's
// MatResidual, and the smoother as a PC (PCSHELL, Richardson's fast path).
#include "sim/slab_gs.h"
#include "sim/slab_gs_lanes.h"

#include <petsc/private/petscimpl.h> // PetscObjectStateGet

using namespace slab_gs_detail;

PetscErrorCode SlabGSHeldOf(PetscObject obj, SlabGS::Held *held)
{
  PetscFunctionBegin;
  PetscCall(PetscObjectGetId(obj, &held->id));
  PetscCall(PetscObjectStateGet(obj, &held->state));
  PetscFunctionReturn(0);
}

namespace {

// lv holds v's values in the lane layout, converted unless held says lv already holds v as it is now
PetscErrorCode LanesOf(SlabGS *gs, Vec v, SlabGS::Held *held, std::vector<double> &lv)
{
  SlabGS::Held now;

  PetscFunctionBegin;
  PetscCall(SlabGSHeldOf((PetscObject)v, &now));
  if (held->id != now.id || held->state != now.state) {
    const PetscScalar *a;
    PetscCall(VecGetArrayRead(v, &a));
    ToLanes(*gs, a, lv);
    PetscCall(VecRestoreArrayRead(v, &a));
    *held = now;
  }
  PetscFunctionReturn(0);
}

// The ghosts' scatter and Vec of a distributed level, made at its first use.
struct HaloScatter {
  VecScatter scatter = nullptr;
  Vec        ghosts  = nullptr;
  ~HaloScatter()
  {
    (void)VecScatterDestroy(&scatter);
    (void)VecDestroy(&ghosts);
  }
};

// lanes -= A_halo x_ghost (x's entries of the other ranks' rows the halo couples to); lanes is gs->bl (the
// sweeps' right-hand side, then no longer b) or gs->rl (a residual)
PetscErrorCode SubtractHalo(SlabGS *gs, Vec x, std::vector<double> &lanes)
{
  constexpr int      L = SlabGS::lanes;
  const PetscScalar *xg;

  PetscFunctionBegin;
  if (!gs->halo_scatter) {
    auto                  h = std::make_shared<HaloScatter>();
    std::vector<PetscInt> dofs;
    IS                    is;
    for (PetscInt node : gs->ghost_nodes)
      for (int i = 0; i < 3; ++i) dofs.push_back(3 * node + i);
    PetscCall(ISCreateGeneral(PETSC_COMM_SELF, (PetscInt)dofs.size(), dofs.data(), PETSC_COPY_VALUES, &is));
    PetscCall(VecCreateSeq(PETSC_COMM_SELF, (PetscInt)dofs.size(), &h->ghosts));
    PetscCall(VecScatterCreate(x, is, h->ghosts, nullptr, &h->scatter));
    PetscCall(ISDestroy(&is));
    gs->halo_scatter = h;
  }
  HaloScatter *h = static_cast<HaloScatter *>(gs->halo_scatter.get());
  PetscCall(VecScatterBegin(h->scatter, x, h->ghosts, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecScatterEnd(h->scatter, x, h->ghosts, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGetArrayRead(h->ghosts, &xg));
  for (size_t k = 0; k < gs->halo.size(); ++k) {
    const double *a = gs->halo_val.data() + 9 * k, *v = xg + 3 * gs->halo[k].ghost;
    double       *t = lanes.data() + LaneIndex(gs->halo[k].row, gs->steps);
    for (int i = 0; i < 3; ++i) t[i * L] -= a[3 * i] * v[0] + a[3 * i + 1] * v[1] + a[3 * i + 2] * v[2];
  }
  PetscCall(VecRestoreArrayRead(h->ghosts, &xg));
  if (&lanes == &gs->bl) gs->held_b = SlabGS::Held(); // bl is no longer b
  PetscCall(PetscLogFlops(18.0 * (double)gs->halo.size()));
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode SlabGSAttach(Mat A, SlabGS *gs)
{
  PetscContainer c;

  PetscFunctionBegin;
  PetscCall(PetscContainerCreate(PetscObjectComm((PetscObject)A), &c));
  PetscCall(PetscContainerSetPointer(c, gs));
  PetscCall(PetscObjectCompose((PetscObject)A, "SlabGS", (PetscObject)c));
  PetscCall(PetscContainerDestroy(&c));
  PetscFunctionReturn(0);
}

PetscErrorCode SlabGSResidualMat(Mat A, Vec b, Vec x, Vec r)
{
  PetscContainer c;
  SlabGS        *gs;
  PetscScalar   *ra;

  PetscFunctionBegin;
  PetscCall(PetscObjectQuery((PetscObject)A, "SlabGS", (PetscObject *)&c));
  PetscCheck(c, PetscObjectComm((PetscObject)A), PETSC_ERR_ARG_WRONG,
             "slab Gauss-Seidel residual: no SlabGS attached to the operator");
  PetscCall(PetscContainerGetPointer(c, (void **)&gs));
  PetscCall(PetscLogEventBegin(SLAB_Residual, A, b, x, r));
  PetscCall(LanesOf(gs, b, &gs->held_b, gs->bl));
  PetscCall(LanesOf(gs, x, &gs->held_x, gs->xl));
  BestBody()(*gs, gs->bl.data(), gs->xl.data(), gs->ll.data(), gs->rl.data(), kResidual);
  if (gs->distributed) PetscCall(SubtractHalo(gs, x, gs->rl)); // the couplings to other ranks' rows
  PetscCall(VecGetArrayWrite(r, &ra));
  FromLanes(*gs, gs->rl, ra);
  PetscCall(VecRestoreArrayWrite(r, &ra));
  PetscCall(PetscLogFlops(2 * 18.0 * (double)gs->val.size() / 9 + 18.0 * gs->n));
  PetscCall(PetscLogEventEnd(SLAB_Residual, A, b, x, r));
  PetscFunctionReturn(0);
}

namespace {

PetscErrorCode SymmetricSweeps(SlabGS *gs, Vec b, Vec x, PetscInt its, PetscBool zero_guess)
{
  PetscScalar *xa;

  PetscFunctionBegin;
  const PassBody body = BestBody();
  PetscCall(PetscLogEventBegin(SLAB_Smooth, 0, 0, 0, 0));
  if (zero_guess) std::fill(gs->xl.begin(), gs->xl.end(), 0.0);
  else PetscCall(LanesOf(gs, x, &gs->held_x, gs->xl));
  for (PetscInt k = 0; k < its; ++k) { // forward from zero: no U products (x of later rows is zero)
    PetscCall(LanesOf(gs, b, &gs->held_b, gs->bl));
    // from a guess on a distributed level, the other ranks' part to the right-hand side (from zero it
    // is zero, on every rank alike: the exchange is collective); x's ghosts as they are now
    if (gs->distributed && (k > 0 || !zero_guess)) {
      if (k > 0) {
        PetscCall(VecGetArrayWrite(x, &xa));
        FromLanes(*gs, gs->xl, xa);
        PetscCall(VecRestoreArrayWrite(x, &xa));
      }
      PetscCall(SubtractHalo(gs, x, gs->bl));
    }
    body(*gs, gs->bl.data(), gs->xl.data(), gs->ll.data(), nullptr,
         zero_guess && k == 0 ? kForwardZero : kForward);
    body(*gs, gs->bl.data(), gs->xl.data(), gs->ll.data(), nullptr, kBackward);
  }
  PetscCall(VecGetArrayWrite(x, &xa));
  FromLanes(*gs, gs->xl, xa);
  PetscCall(VecRestoreArrayWrite(x, &xa));
  PetscCall(SlabGSHeldOf((PetscObject)x, &gs->held_x)); // xl holds x as it is now
  // per symmetric sweep: U products twice, the pushes once (each 18 flops per stored block), the solves
  PetscCall(PetscLogFlops(its * (3 * 18.0 * (double)gs->val.size() / 9 + 2 * 15.0 * gs->n)));
  PetscCall(PetscLogEventEnd(SLAB_Smooth, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

PetscErrorCode ApplyRichardson(PC pc, Vec b, Vec x, Vec, PetscReal, PetscReal, PetscReal, PetscInt its,
                               PetscBool zero_guess, PetscInt *outits, PCRichardsonConvergedReason *reason)
{
  SlabGS *gs;

  PetscFunctionBegin;
  PetscCall(PCShellGetContext(pc, &gs));
  PetscCall(SymmetricSweeps(gs, b, x, its, zero_guess));
  *outits = its;
  *reason = PCRICHARDSON_CONVERGED_ITS;
  PetscFunctionReturn(0);
}

PetscErrorCode Apply(PC pc, Vec b, Vec x)
{
  SlabGS *gs;

  PetscFunctionBegin;
  PetscCall(PCShellGetContext(pc, &gs));
  PetscCall(SymmetricSweeps(gs, b, x, 1, PETSC_TRUE));
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode SlabGSApplySweeps(SlabGS *gs, Vec b, Vec x, PetscInt its, PetscBool zero_guess)
{
  PetscFunctionBegin;
  PetscCall(SlabGSRegisterEvents());
  PetscCall(SymmetricSweeps(gs, b, x, its, zero_guess));
  PetscFunctionReturn(0);
}

PetscErrorCode SlabGSSetPC(PC pc, SlabGS *gs, PetscBool whole)
{
  PetscFunctionBegin;
  PetscCall(SlabGSRegisterEvents());
  PetscCall(PCSetType(pc, PCSHELL));
  PetscCall(PCShellSetContext(pc, gs));
  PetscCall(PCShellSetApply(pc, Apply));
  if (whole) PetscCall(PCShellSetApplyRichardson(pc, ApplyRichardson));
  PetscCall(PCShellSetName(pc, "slab Gauss-Seidel (symmetric sweep, 8 rows side by side)"));
  PetscFunctionReturn(0);
}
