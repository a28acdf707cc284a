// The batched element loop reads the node arrays (x, v, rest positions) of a full batch with one 4-wide
// load per node triple in the AVX-512 body: each such load reads one double past its triple, so the
// triple that ends an array is loaded masked. Here the three arrays end exactly where an inaccessible
// page begins: a load past the last triple faults (the test dies), and the bodies' results on the
// guarded arrays equal the portable body's on ordinary ones. (valgrind, which would see the over-read
// too, runs only the portable bodies: it cannot decode AVX-512.)
#include <catch2/catch.hpp>

#include "physics/corotational_assembly.hpp"
#include "physics/element_batch.hpp"
#include "physics/fem_model.hpp"
#include "physics/tet_mesh.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

using namespace physics;

namespace {

// n doubles that end where a PROT_NONE page begins.
class GuardedArray {
public:
  explicit GuardedArray(const std::vector<double> &from)
  {
    const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE)),
                      used = from.size() * sizeof(double);
    length_                = (used + page - 1) / page * page + page;
    base_ = mmap(nullptr, length_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    REQUIRE(base_ != MAP_FAILED);
    REQUIRE(mprotect(static_cast<char *>(base_) + length_ - page, page, PROT_NONE) == 0);
    data_ = reinterpret_cast<double *>(static_cast<char *>(base_) + length_ - page - used);
    std::memcpy(data_, from.data(), used);
  }
  ~GuardedArray() { munmap(base_, length_); }
  GuardedArray(const GuardedArray &)            = delete;
  GuardedArray &operator=(const GuardedArray &) = delete;
  const double *data() const { return data_; }

private:
  void       *base_   = nullptr;
  std::size_t length_ = 0;
  double     *data_   = nullptr;
};

// n disjoint tetrahedra (element e: nodes 4e..4e+3), each a little deformed and rotated, in the order
// given (P2: promoted, the edge nodes after the corners).
TetMesh disjoint_elements(int order, int n, std::mt19937 &rng)
{
  std::uniform_real_distribution<double> u(-1, 1);
  TetMesh                                lin;
  lin.order = 1;
  for (int e = 0; e < n; ++e) {
    const double c[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int a = 0; a < 4; ++a) {
      for (int d = 0; d < 3; ++d) lin.nodes.push_back(0.3 * e + c[a][d] + 0.05 * u(rng));
      lin.elements.push_back(4 * e + a);
    }
  }
  return order == 2 ? promote_to_quadratic(lin) : lin;
}

} // namespace

TEST_CASE("the AVX-512 element gather reads nothing past the node arrays", "[fem][kernel][batch]")
{
  const ElementBatchBody avx512 = element_batch_avx512(), portable = element_batch_portable();
  if (element_body_used(binbcsr::BodySet::AVX512) != binbcsr::BodySet::AVX512 || !avx512) {
    WARN("element body avx512 not run: this CPU or build lacks it");
    return;
  }
  REQUIRE(portable);
  for (int order : {1, 2}) {
    INFO("order " << order);
    std::mt19937 rng(41 + order);
    const int    n = 2 * kElementLanes; // full batches only: every batch takes the 4-wide gather
    FemSettings  settings;
    settings.young        = 3e5;
    settings.poisson      = 0.3;
    settings.corotational = true;
    const FemModel m      = make_fem_model(disjoint_elements(order, n, rng), settings);
    const int      npe    = m.npe;
    // The last element first: the array's last node is gathered in the first batch and in lane 0.
    std::vector<int> elements(n);
    for (int e = 0; e < n; ++e) elements[e] = n - 1 - e;
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<double>                    x = m.mesh.nodes, v(x.size());
    for (double &c : x) c *= 1.0 + 0.01 * u(rng);
    for (double &w : v) w = u(rng);
    const std::vector<char> fixed(m.node_count(), 0);
    const BlockPattern      p = make_block_pattern(m, elements, fixed, 0, m.node_count(), true);
    REQUIRE(*std::max_element(p.plan.element_nodes.begin(), p.plan.element_nodes.end()) ==
            m.node_count() - 1);
    const GuardedArray     gx(x), gv(v), gX(m.mesh.nodes);
    const StepCoefficients c = implicit_euler_coefficients(0.01, 0.5, 0.002);
    double                 Mref[100];
    for (int a = 0; a < npe; ++a)
      for (int b = 0; b < npe; ++b) Mref[npe * a + b] = m.reference_mass(a, b);

    // The dispatch's arguments (element_batch.cpp), the node arrays from the guarded copies or not.
    auto run = [&](ElementBatchBody body, bool guarded, std::vector<double> &rhs,
                   std::vector<double> &values) {
      rhs.assign(x.size(), 0.0);
      reset_block_values(p, values);
      ElementBatchArgs a;
      a.npe            = npe;
      a.corotational   = true;
      a.listed_nodes   = p.plan.element_nodes.data();
      a.count          = elements.size();
      a.nodes          = static_cast<std::size_t>(m.node_count());
      a.rest_positions = guarded ? gX.data() : m.mesh.nodes.data();
      a.reference_mass = Mref;
      a.x              = guarded ? gx.data() : x.data();
      a.v              = guarded ? gv.data() : v.data();
      a.values         = values.data();
      a.rhs            = rhs.data();
      a.group_offsets  = p.plan.group_offsets.data();
      a.write_slots    = p.plan.write_slots.data();
      a.group_terms    = p.plan.group_terms.data();
      a.run_offsets    = p.plan.run_offsets.data();
      a.runs           = p.plan.runs.data();
      a.write_terms    = p.plan.write_terms.data();
      a.k              = kernels::ElementConstants{c.force,       c.stiffness_rhs,    c.mass_rhs,
                                      c.mass_matrix, c.stiffness_matrix, m.lame.lambda,
                                      m.lame.mu,     m.settings.density};
      return body(a);
    };
    std::vector<double> rhs_ref, values_ref, rhs, values;
    const long long     ref_path = run(portable, false, rhs_ref, values_ref);
    const long long     path     = run(avx512, true, rhs, values);
    CHECK(path == ref_path);
    const double rhs_scale =
      std::max(1e-300, *std::max_element(rhs_ref.begin(), rhs_ref.end(),
                                         [](double a, double b) { return std::fabs(a) < std::fabs(b); }));
    const double value_scale =
      std::max(1e-300, *std::max_element(values_ref.begin(), values_ref.end(),
                                         [](double a, double b) { return std::fabs(a) < std::fabs(b); }));
    double rhs_diff = 0, value_diff = 0;
    for (std::size_t k = 0; k < rhs.size(); ++k)
      rhs_diff = std::max(rhs_diff, std::fabs(rhs[k] - rhs_ref[k]));
    for (std::size_t k = 0; k < values.size(); ++k)
      value_diff = std::max(value_diff, std::fabs(values[k] - values_ref[k]));
    // Rounding only (FMA contraction, the order of sums): the same bounds as the body-against-portable
    // comparison of element_kernels.cpp.
    CHECK(rhs_diff <= 1e-10 * std::fabs(rhs_scale));
    CHECK(value_diff <= 1e-13 * std::fabs(value_scale));
  }
}
