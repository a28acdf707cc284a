// The dispatch of the batched element loop (element_batch.hpp): flattens the model into
// ElementBatchArgs and runs the body of the chosen set.
#include "physics/element_batch.hpp"
#include "physics/corotational_assembly.hpp"
#include "physics/polar_decomposition.hpp"

namespace physics {

namespace {

// The set's body where this CPU runs the set and this build compiled it, else null.
ElementBatchBody body_of(binbcsr::BodySet set)
{
  if (!binbcsr::cpu_runs(set)) return nullptr;
  switch (set) {
  case binbcsr::BodySet::AVX2:
    return element_batch_avx2();
  case binbcsr::BodySet::AVX512:
    return element_batch_avx512();
  default:
    return element_batch_portable();
  }
}

} // namespace

binbcsr::BodySet element_body_used(binbcsr::BodySet want)
{
  using binbcsr::BodySet;
  static const bool    avx2 = body_of(BodySet::AVX2) != nullptr, avx512 = body_of(BodySet::AVX512) != nullptr;
  static const BodySet best = avx512 ? BodySet::AVX512 : avx2 ? BodySet::AVX2 : BodySet::Portable;
  if (want == BodySet::Portable || (want == BodySet::AVX2 && avx2) || (want == BodySet::AVX512 && avx512))
    return want;
  return best;
}

void element_fallback_rotation(const double *F, double *R)
{
  Eigen::Matrix3d::Map(R) = rotation_from_deformation(Eigen::Matrix3d::Map(F));
}

namespace {

// The call's arguments for the bodies; the blocks into values or values_single (one of them, or none).
long long run_batched(const FemModel &model, const std::vector<int> &elements, const double *x,
                      const double *v, const StepCoefficients &c, const BlockPattern *pattern, double *values,
                      float *values_single, double *rhs, double *rotations, binbcsr::BodySet body,
                      ElementEnergy *energy)
{
  if (elements.empty()) return 0;
  static_assert(sizeof(Eigen::Matrix3d) == 9 * sizeof(double), "Dm^-1 is read as 9 packed doubles");
  const int npe = model.npe;
  double    Mref[100]; // row-major, up to 10 x 10
  for (int a = 0; a < npe; ++a)
    for (int b = 0; b < npe; ++b) Mref[npe * a + b] = model.reference_mass(a, b);
  ElementBatchArgs args;
  args.npe          = npe;
  args.corotational = model.settings.corotational;
  std::vector<int> listed; // without a pattern (forces only): copied here
  const bool       planned = pattern && pattern->plan.element_nodes.size() == elements.size() * npe;
  if (!planned) listed = listed_element_nodes(model, elements);
  args.listed_nodes   = planned ? pattern->plan.element_nodes.data() : listed.data();
  args.count          = elements.size();
  args.nodes          = static_cast<std::size_t>(model.node_count());
  args.rest_positions = model.mesh.nodes.data();
  args.reference_mass = Mref;
  args.diagonal_mass  = model.diagonal_mass;
  args.x              = x;
  args.v              = v;
  args.values         = values;
  args.values_single  = values_single;
  args.rhs            = rhs;
  args.rotations      = rotations;
  double sums[3]      = {0, 0, 0};
  if (energy) {
    args.energy         = sums;
    args.element_energy = energy->per_element;
  }
  args.k = kernels::ElementConstants{c.force,       c.stiffness_rhs,       c.mass_rhs,
                                     c.mass_matrix, c.stiffness_matrix,    model.lame.lambda,
                                     model.lame.mu, model.settings.density};
  if (values || values_single) {
    args.group_offsets = pattern->plan.group_offsets.data();
    args.write_slots   = pattern->plan.write_slots.data();
    args.group_terms   = pattern->plan.group_terms.data();
    args.run_offsets   = pattern->plan.run_offsets.data();
    args.runs          = pattern->plan.runs.data();
    args.write_terms   = pattern->plan.write_terms.data();
  }
  const long long fallbacks = body_of(element_body_used(body))(args);
  if (energy) {
    energy->elastic += sums[0];
    energy->kinetic += sums[1];
    energy->inverted += sums[2];
  }
  return fallbacks;
}

} // namespace

long long assemble_elements_batched(const FemModel &model, const std::vector<int> &elements, const double *x,
                                    const double *v, const StepCoefficients &c, const BlockPattern *pattern,
                                    double *values, double *rhs, double *rotations, binbcsr::BodySet body,
                                    ElementEnergy *energy)
{
  return run_batched(model, elements, x, v, c, pattern, values, nullptr, rhs, rotations, body, energy);
}

long long assemble_elements_batched_single(const FemModel &model, const std::vector<int> &elements,
                                           const double *x, const double *v, const StepCoefficients &c,
                                           const BlockPattern *pattern, float *values, double *rhs,
                                           double *rotations, binbcsr::BodySet body, ElementEnergy *energy)
{
  return run_batched(model, elements, x, v, c, pattern, nullptr, values, rhs, rotations, body, energy);
}

double element_kernel_flops(int order, bool with_blocks)
{
  // Counted from the kernels, a multiply-add as 2: deformation gradient 63; Newton 2 scaled steps of
  // about 110 and 3 plain ones of about 80. P1: forces about 360, blocks 670. P2: forces about 1,650;
  // blocks: 16 rotated gradient pairs of 40, 55 blocks of 4 (padded) terms of 18, and the mass.
  const double rotation = 63 + 2 * 110 + 3 * 80;
  if (order == 1) return rotation + 360 + (with_blocks ? 670 : 0);
  return rotation + 1650 + (with_blocks ? 16 * 40 + 55 * (4 * 18 + 10) : 0);
}

} // namespace physics
