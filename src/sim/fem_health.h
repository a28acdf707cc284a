// The FEM scene's health figures for the run guard (sim/run_guard.h), shared by the fem driver and
// the tests: what the scene states as healthy and what a state measures.
#pragma once
#include "sim/fem_simulation.h"
#include "sim/run_guard.h"

// Kinetic + elastic energy + the potential of gravity: implicit Euler only loses it, so a gain is the
// integration (or the solver) breaking down.
double FemTotalEnergy(const FemSimulation &sim);
// Fraction of the elements whose corner tetrahedron is inverted or flat.
double FemInvertedFraction(const FemSimulation &sim);
// The energy scale is the free nodes' weight times the body's diagonal plus the energy the state holds
// now (call it on the initial state); energy may grow by 0.5 of it, and no element may invert that was
// not inverted at the start.
HealthBounds FemHealthBounds(const FemSimulation &sim);
