// Positions written at the end of a run and compared with another run's: the error measure of the
// speed/accuracy study (bench/tradeoff.sh), the position difference against a tightly converged
// reference run after the same simulated time.
//   -write_positions FILE      rank 0 writes every position (x y z per line, full precision)
//   -reference_positions FILE  the summary gets rms_position_diff and max_position_diff (m) against FILE
#pragma once
#include "sim/summary.h"

#include <petscsys.h>

#include <vector>

// Reads the two options; `xyz`: the full state's positions (3 per point, the same on every rank).
// Errors when the reference has another number of points or cannot be read.
PetscErrorCode DriverComparePositions(MPI_Comm comm, const std::vector<double> &xyz, SummaryLine &s);
