#include "sim/summary.h"

#include <ctime>

#include <cstdio>

void SummaryLine::add(const std::string &key, double value)
{
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", value);
  fields.emplace_back(key, buf);
}

void SummaryLine::add(const std::string &key, long long value)
{
  fields.emplace_back(key, std::to_string(value));
}

void SummaryLine::add(const std::string &key, const std::string &value) { fields.emplace_back(key, value); }

double StepCosts::total_ms() const
{
  double ms = 0;
  for (const Step &step : steps) ms += step.ms;
  return ms;
}

void StepCosts::add_late(SummaryLine &s) const
{
  double       ms  = 0;
  long long    its = 0, solves = 0;
  const size_t late = steps.size() / 2;
  for (size_t k = late; k < steps.size(); ++k)
    ms += steps[k].ms, its += steps[k].iterations, solves += steps[k].solves;
  const size_t n = steps.size() - late;
  s.add("late_ms_per_step", n ? ms / (double)n : 0.0);
  s.add("late_cg_its", solves ? (double)its / (double)solves : 0.0);
}

PetscErrorCode PrintSummary(MPI_Comm comm, const SummaryLine &line)
{
  std::string text = "summary";
  PetscFunctionBegin;
  for (const auto &kv : line.fields) text += " " + kv.first + "=" + kv.second;
  PetscCall(PetscPrintf(comm, "%s\n", text.c_str()));
  PetscFunctionReturn(0);
}

double WallTime() { return MPI_Wtime(); }

double ProcessCpuTime()
{
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
