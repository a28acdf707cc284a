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

// Prints on rank 0 of comm.
PetscErrorCode PrintSummary(MPI_Comm comm, const SummaryLine &line);

// Wall-clock seconds (MPI_Wtime), for the per-step timings the drivers report.
double WallTime();

// CPU seconds of this process (all threads): leaves out the time it was descheduled, for timings on a
// machine shared with other jobs (memory and cache contention still count; MPI waits that poll count).
double ProcessCpuTime();
