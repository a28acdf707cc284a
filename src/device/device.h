/*
   The device library: BIN-(B)CSR bins, their refill, their products and the merged CG (Jacobi) on a
   device, behind one interface with two executors (the model of Ginkgo and libCEED):

     reference  host, serial, always built: the per-lane bodies of binbcsr_kernels.h and the
                per-index bodies of mcg_kernels.h called in plain loops; the definition the other
                executor is tested against;
     cuda       NVIDIA GPUs, built where nvcc is found: the same bodies, one thread per lane / index.

   No PETSc and no MPI here: a machine with a GPU and CUDA but no PETSc builds and tests this library
   with nvcc alone (scripts/gpu_check). The PETSc glue (src/mat_binbcsr/seq/binbcsr_device.cpp,
   src/ksp_mcg/mcg_device_solve.cpp) maps MATSEQBINBCSR and KSPMCG onto it.

   Ownership: a Matrix owns its bins on the device (values in double or single, columns, bin starts,
   whole or symmetric storage) and its refill map; a Vector owns n doubles on the device. Host arrays
   passed in are copied; nothing keeps a pointer to them.
*/
#ifndef BINBCSR_DEVICE_H
#define BINBCSR_DEVICE_H

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace binbcsr {
namespace device {

enum class Precision {
  double_values,
  single_values
};

/* The bins as MATSEQBINBCSR lays them out (src/mat_binbcsr/seq/binbcsr.h): bin_start[nbins + 1],
   col[nslots]; whole storage, or symmetric storage (upper triangle, slots coloured so that the lanes of
   one slot group scatter to distinct columns; padding slots have the lane's own row as column). */
struct Layout {
  int        bs = 3, bw = 8, mbs = 0;
  bool       symmetric = false;
  const int *bin_start = nullptr; /* [nbins() + 1] */
  const int *col       = nullptr; /* [nslots()] */
  int        nbins() const { return (mbs + bw - 1) / bw; }
  long       nslots() const { return bin_start ? bin_start[nbins()] : 0; }
  long       nvalues() const { return nslots() * bs * bs; }
  long       n() const { return (long)mbs * bs; }
};

/* The refill map (the seed's Listing 2.9): stored value v (index into the bins' value array, padding
   included) is the sum of the COO values perm[jmap[v] .. jmap[v + 1] - 1]; padding has no entries. */
struct GatherMap {
  long       ncoo = 0;       /* length of the COO value array */
  const int *jmap = nullptr; /* [nvalues + 1] */
  const int *perm = nullptr; /* [jmap[nvalues]], each < ncoo */
};

/* Norm the CG reports and tests (KSPNormType's meanings). */
enum class Norm {
  preconditioned,
  unpreconditioned,
  natural,
  none
};

/* Why a solve stopped; the numbers are PETSc's KSPConvergedReason values, so the glue maps one to one. */
enum Reason : int {
  iterating               = 0,
  converged_rtol          = 2,
  converged_atol          = 3,
  converged_its           = 4,
  diverged_its            = -3,
  diverged_dtol           = -4,
  diverged_breakdown      = -5,
  diverged_indefinite_pc  = -8,
  diverged_nanorinf       = -9,
  diverged_indefinite_mat = -10
};

struct SolveSettings {
  bool   jacobi     = true; /* z = dinv r (dinv given to solve); false: z = r */
  Norm   norm       = Norm::preconditioned;
  int    max_its    = 10000;
  int    fixed_its  = 0;    /* > 0: exactly this many iterations, no test, no host synchronisation */
  bool   guess_zero = true; /* false: x holds the initial guess, r = b - A x */
  double rtol = 1e-5, atol = 1e-50, dtol = 1e5;
  int    check_every = 8; /* the host looks at the state every k iterations (one small copy) */
  /* KSPMCG's true-residual check before a claim within 100x the estimated rounding drift, with
     restarts that must shrink the true residual by `stagnation` (-ksp_mcg_verify_residual) */
  bool   verify     = true;
  double stagnation = 0.5;
  /* relative rounding u of the products (single storage): no tolerance is claimed below u ||A|| ||x||
     (KSPMCG's precision floor); 0: off */
  double roundoff = 0.0;
  /* Called once with the initial norm dp0: sets the absolute tolerance ttol and the divergence bound
     (PETSc's KSPConvergedDefault decides them; default: max(rtol dp0, atol) and dtol dp0). */
  std::function<void(double dp0, double &ttol, double &divergence)> at_start;
};

struct SolveResult {
  int                 its    = 0;
  int                 reason = iterating;
  double              rnorm  = 0.0;
  std::vector<double> history;         /* the norm at iterations 0 .. its (none with fixed_its) */
  int                 host_syncs  = 0; /* copies of the state to the host during the solve */
  int                 true_checks = 0, restarts = 0;
  double              true_rnorm = -1.0;
};

class Vector {
public:
  virtual ~Vector()                      = default;
  virtual long size() const              = 0;
  virtual void upload(const double *h)   = 0;
  virtual void download(double *h) const = 0;
};

class Matrix {
public:
  virtual ~Matrix()                       = default;
  virtual const Layout &layout() const    = 0;
  virtual Precision     precision() const = 0;
  /* The whole value array in the bins' layout (nvalues doubles, padding zero), rounded to the storage. */
  virtual void set_values(const double *val) = 0;
  virtual void get_values(double *val) const = 0;
  /* Refill from COO values: upload ncoo values and gather on the device, one thread per lane. */
  virtual void set_gather_map(const GatherMap &map)        = 0;
  virtual void refill(const double *coo, bool add = false) = 0;
  /* y = A x */
  virtual void mult(const Vector &x, Vector &y) = 0;
  /* y = A x, returns x.y (one pass) */
  virtual double mult_dot(const Vector &x, Vector &y) = 0;
  /* The merged CG: b and x on the device (x: the guess in, the solution out), dinv the inverse diagonal
     (used when settings.jacobi). */
  virtual SolveResult solve(const Vector &dinv, const Vector &b, Vector &x,
                            const SolveSettings &settings) = 0;
};

class Executor {
public:
  virtual ~Executor()                                                               = default;
  virtual const char             *name() const                                      = 0;
  virtual std::unique_ptr<Vector> vector(long n)                                    = 0;
  virtual std::unique_ptr<Matrix> matrix(const Layout &layout, Precision precision) = 0;
  virtual void                    synchronize()                                     = 0;
};

/* "reference" or "cuda"; nullptr and *why (why not: not built, no device, ...) when it cannot be made. */
std::unique_ptr<Executor> make_executor(const std::string &name, std::string *why);
/* Whether this build has the cuda executor. */
bool cuda_built();

} // namespace device
} // namespace binbcsr

#endif
