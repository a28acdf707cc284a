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
