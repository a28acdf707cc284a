// gmsh .msh reader: both ASCII formats, tet4 and tet10 (edge order), unused nodes dropped, and a
// clear error for each kind of broken file.
#include <catch2/catch.hpp>

#include "physics/fem_model.hpp"
#include "physics/msh_reader.hpp"

#include <cmath>
#include <sstream>
#include <string>

using namespace physics;

namespace {

// One unit tetrahedron plus a triangle and an unused node, format 2.2.
const char *kMsh22 = R"($MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
1
3 1 "body"
$EndPhysicalNames
$Nodes
6
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1
7 5 5 5
9 0.5 0.5 0
$EndNodes
$Elements
2
1 2 2 0 1 1 2 3
2 4 2 1 1 1 2 3 4
$EndElements
)";

// The same tetrahedron as a 10-node element, format 4.1; gmsh's edge order 01 12 20 30 32 31.
std::string msh41_tet10()
{
  const double       c[4][3]          = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int          gmsh_edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}};
  std::ostringstream s;
  s << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities\n";
  s << "$Nodes\n1 10 1 10\n3 1 0 10\n";
  for (int i = 1; i <= 10; ++i) s << i << "\n";
  for (int i = 0; i < 4; ++i) s << c[i][0] << " " << c[i][1] << " " << c[i][2] << "\n";
  for (const auto &e : gmsh_edges)
    s << 0.5 * (c[e[0]][0] + c[e[1]][0]) << " " << 0.5 * (c[e[0]][1] + c[e[1]][1]) << " "
      << 0.5 * (c[e[0]][2] + c[e[1]][2]) << "\n";
  s << "$EndNodes\n$Elements\n1 1 1 1\n3 1 11 1\n1 1 2 3 4 5 6 7 8 9 10\n$EndElements\n";
  return s.str();
}

std::string error_of(const std::string &text)
{
  std::istringstream in(text);
  try {
    read_msh(in, "test.msh");
  } catch (const std::runtime_error &e) {
    return e.what();
  }
  return "";
}

std::string replace(std::string s, const std::string &from, const std::string &to)
{
  const auto p = s.find(from);
  REQUIRE(p != std::string::npos);
  return s.replace(p, from.size(), to);
}

} // namespace

TEST_CASE("msh 2.2: tetrahedra read, other elements and unused nodes dropped", "[fem][msh]")
{
  std::istringstream in(kMsh22);
  const TetMesh      m = read_msh(in, "t.msh");
  CHECK(m.order == 1);
  CHECK(m.element_count() == 1);
  CHECK(m.node_count() == 4);
  CHECK(element_signed_volume(m, m.nodes.data(), 0) == Approx(1.0 / 6));
}

TEST_CASE("msh 4.1 tet10: edge nodes land at the midpoints of our edges", "[fem][msh]")
{
  std::istringstream in(msh41_tet10());
  const TetMesh      m = read_msh(in, "t.msh");
  REQUIRE(m.order == 2);
  REQUIRE(m.element_count() == 1);
  for (int k = 0; k < 6; ++k) {
    const int a = m.elements[kTetEdges[k][0]], b = m.elements[kTetEdges[k][1]], mid = m.elements[4 + k];
    for (int d = 0; d < 3; ++d)
      CHECK(m.nodes[3 * mid + d] == Approx(0.5 * (m.nodes[3 * a + d] + m.nodes[3 * b + d])));
  }
}

TEST_CASE("malformed msh files give clear errors", "[fem][msh]")
{
  const std::string good = kMsh22;
  CHECK_THAT(error_of(""), Catch::Contains("no $MeshFormat"));
  CHECK_THAT(error_of(replace(good, "2.2 0 8", "2.2 1 8")), Catch::Contains("binary"));
  CHECK_THAT(error_of(replace(good, "2.2 0 8", "3.0 0 8")), Catch::Contains("unsupported .msh version"));
  CHECK_THAT(error_of(replace(good, "$Nodes\n6", "$Nodes\n7")), Catch::Contains("section ended early"));
  CHECK_THAT(error_of(replace(good, "$Nodes\n6", "$Nodes\n5")), Catch::Contains("expected $EndNodes"));
  CHECK_THAT(error_of(replace(good, "2 4 2 1 1 1 2 3 4", "2 4 2 1 1 1 2 3 8")),
             Catch::Contains("undefined node 8"));
  CHECK_THAT(error_of(replace(good, "3 0 1 0", "3 0 x 0")), Catch::Contains("expected y"));
  CHECK_THAT(error_of(replace(good, "7 5 5 5", "1 5 5 5")), Catch::Contains("duplicate node tag 1"));
  CHECK_THAT(error_of(replace(good, "2 4 2 1 1 1 2 3 4", "2 2 2 1 1 1 2 3")),
             Catch::Contains("no tetrahedra"));
  CHECK_THAT(error_of(replace(good, "2 4 2 1 1 1 2 3 4", "2 4 2 1 1 1 3 2 4")),
             Catch::Contains("inverted or of zero volume"));
  CHECK_THAT(error_of(replace(good, "4 0 0 1", "4 1 1 0")), Catch::Contains("inverted or of zero volume"));
  // The inverted element is named by its tag in the file (2), not by its index in the mesh (0).
  CHECK_THAT(error_of(replace(good, "2 4 2 1 1 1 2 3 4", "2 4 2 1 1 1 3 2 4")),
             Catch::Contains("first: element with tag 2 "));
  // A misspelt header is named where it stands, not skipped to the end of the file.
  CHECK_THAT(error_of(replace(good, "$MeshFormat\n", "$MeshFmt\n")),
             Catch::Contains("test.msh:1: expected $MeshFormat as the first section, found '$MeshFmt'"));
  CHECK_THAT(error_of(replace(good, "$EndElements\n", "")), Catch::Contains("missing $EndElements"));
  const std::string no_elements = good.substr(0, good.find("$Elements"));
  CHECK_THAT(error_of(no_elements), Catch::Contains("no $Elements"));
  CHECK_THAT(error_of(replace(good, "$EndPhysicalNames\n", "")), Catch::Contains("not terminated"));
  CHECK_THAT(error_of(replace(good, "$EndPhysicalNames\n", "")), Catch::Contains("opened at line"));
  // Mixed orders.
  std::string mixed = replace(good, "$Elements\n2", "$Elements\n3");
  mixed             = replace(mixed, "$EndElements", "3 11 2 1 1 1 2 3 4 1 2 3 4 1 2\n$EndElements");
  CHECK_THAT(error_of(mixed), Catch::Contains("mixes linear"));
  // 4.1 count mismatch.
  CHECK_THAT(error_of(replace(msh41_tet10(), "$Nodes\n1 10 1 10", "$Nodes\n1 11 1 11")),
             Catch::Contains("announces 11 nodes"));
  // Error messages carry the file name and line.
  CHECK_THAT(error_of(replace(good, "3 0 1 0", "3 0 x 0")), Catch::Contains("test.msh:12:"));
  CHECK_THROWS_WITH(read_msh_file("/nonexistent/file.msh"), Catch::Contains("cannot open"));
}

TEST_CASE("curved 10-node elements are refused by the model with a clear message", "[fem][msh]")
{
  std::istringstream in(msh41_tet10());
  TetMesh            m = read_msh(in, "t.msh");
  m.nodes[3 * m.elements[4] + 2] += 0.05; // bend edge (0,1) out of line
  CHECK_THROWS_WITH(make_fem_model(m, FemSettings{}), Catch::Contains("curved 10-node"));
}
