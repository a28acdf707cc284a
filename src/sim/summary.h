// What every driver prints at the end: one line `summary key=value ...` that scripts and tests parse.
#pragma once
#include <petscsys.h>
#include <string>
#include <utility>
#include <vector>

struct SummaryLine {
  std::vector<std::pair<std::string, std::string>> fields;
  void                                             add(const std::string &key, double value);
  void                                             add(const std::string &key, long long value);
  void                                             add(const std::string &key, const std::string &value);
};

// Each step's time and solver work, for the summary's late_* fields: means over the second half of
// the steps run (steps n/2 + 1 .. n), the cost of a step once the first steps' one-off work is behind
// (a preconditioner's set-up and copies, the history an initial guess is made from), which the run's
// means include and a long run spreads thin.
struct StepCosts {
  struct Step {
    double    ms;
    long long iterations, solves;
  };
  std::vector<Step> steps;
  void   add(double ms, long long iterations, long long solves) { steps.push_back({ms, iterations, solves}); }
  double total_ms() const; // all steps
  // late_ms_per_step and late_cg_its (Krylov iterations per solve, as cg_its).
  void add_late(SummaryLine &s) const;
};

// Prints on rank 0 of comm.
PetscErrorCode PrintSummary(MPI_Comm comm, const SummaryLine &line);

// Wall-clock seconds (MPI_Wtime), for the per-step timings the drivers report.
double WallTime();

// CPU seconds of this process (all threads): leaves out the time it was descheduled, for timings on a
// machine shared with other jobs (memory and cache contention still count; MPI waits that poll count).
double ProcessCpuTime();
