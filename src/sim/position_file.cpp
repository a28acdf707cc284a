#include "sim/position_file.h"

#include <cmath>
#include <cstdio>

PetscErrorCode DriverComparePositions(MPI_Comm comm, const std::vector<double> &xyz, SummaryLine &s)
{
  char        path[PETSC_MAX_PATH_LEN];
  PetscBool   set;
  PetscMPIInt rank;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-write_positions", path, sizeof path, &set));
  if (set) {
    int ok = 1;
    if (!rank) {
      FILE *f = std::fopen(path, "w");
      ok      = f != nullptr;
      for (size_t i = 0; ok && i + 2 < xyz.size(); i += 3)
        ok = std::fprintf(f, "%.17g %.17g %.17g\n", xyz[i], xyz[i + 1], xyz[i + 2]) > 0;
      if (f) ok &= std::fclose(f) == 0;
    }
    PetscCallMPI(MPI_Bcast(&ok, 1, MPI_INT, 0, comm));
    PetscCheck(ok, comm, PETSC_ERR_FILE_WRITE, "-write_positions: cannot write %s", path);
  }
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-reference_positions", path, sizeof path, &set));
  if (!set) PetscFunctionReturn(0);
  // every rank holds the whole state: each reads the file (small) and computes the same figures
  std::vector<double> ref;
  FILE               *f = std::fopen(path, "r");
  PetscCheck(f, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "-reference_positions: cannot open %s", path);
  double v;
  while (ref.size() <= xyz.size() && std::fscanf(f, "%lf", &v) == 1) ref.push_back(v);
  std::fclose(f);
  PetscCheck(ref.size() == xyz.size(), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED,
             "-reference_positions %s: %zu numbers, this run has %zu positions (%zu numbers)", path,
             ref.size(), xyz.size() / 3, xyz.size());
  double sum = 0, worst = 0;
  for (size_t i = 0; i < xyz.size(); i += 3) {
    const double d2 = (xyz[i] - ref[i]) * (xyz[i] - ref[i]) +
                      (xyz[i + 1] - ref[i + 1]) * (xyz[i + 1] - ref[i + 1]) +
                      (xyz[i + 2] - ref[i + 2]) * (xyz[i + 2] - ref[i + 2]);
    sum += d2;
    worst = std::fmax(worst, std::sqrt(d2));
  }
  s.add("rms_position_diff", xyz.empty() ? 0.0 : std::sqrt(sum / (double)(xyz.size() / 3)));
  s.add("max_position_diff", worst);
  PetscFunctionReturn(0);
}
