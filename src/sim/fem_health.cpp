#include "sim/fem_health.h"

#include "physics/tet_mesh.hpp"

#include <cmath>

double FemTotalEnergy(const FemSimulation &sim)
{
  const physics::FemEnergy e = physics::fem_energy(sim.model, sim.x.data(), sim.v.data());
  double                   w = 0;
  for (size_t k = 0; k < sim.x.size(); ++k) w += sim.f_gravity[k] * (sim.x[k] - sim.model.mesh.nodes[k]);
  return e.kinetic + e.elastic - w;
}

double FemInvertedFraction(const FemSimulation &sim)
{
  const int n   = sim.model.element_count();
  long long bad = 0;
  for (int e = 0; e < n; ++e) bad += !(physics::element_signed_volume(sim.model.mesh, sim.x.data(), e) > 0);
  return n ? (double)bad / n : 0.0;
}

HealthBounds FemHealthBounds(const FemSimulation &sim)
{
  double weight[3] = {0, 0, 0};
  for (int i = 0; i < sim.model.node_count(); ++i)
    if (!sim.fixed[i])
      for (int d = 0; d < 3; ++d) weight[d] += sim.f_gravity[3 * i + d];
  const auto   bb = physics::bounding_box(sim.model.mesh);
  const double diag =
    std::sqrt(std::pow(bb[3] - bb[0], 2) + std::pow(bb[4] - bb[1], 2) + std::pow(bb[5] - bb[2], 2));
  // The state's energy terms from its element pass where it ran (FemSimulationAssembleState), else by
  // the definition (fem_energy, which builds every element's K0 for its walk).
  physics::FemEnergy e0;
  if (FemStateAssembled(sim)) e0.kinetic = sim.state_kinetic, e0.elastic = sim.state_elastic;
  else e0 = physics::fem_energy(sim.model, sim.x.data(), sim.v.data());
  HealthBounds hb;
  hb.energy_scale = std::sqrt(weight[0] * weight[0] + weight[1] * weight[1] + weight[2] * weight[2]) * diag +
                    std::abs(e0.kinetic) + std::abs(e0.elastic);
  hb.energy_growth     = 0.5;
  hb.inverted_fraction = 0;
  return hb;
}
