#include "physics/msh_reader.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace physics {

namespace {

class MshParser {
public:
  MshParser(std::istream &in, std::string name) : in_(in), name_(std::move(name)) {}

  [[noreturn]] void fail(const std::string &what) const
  {
    throw std::runtime_error(name_ + ":" + std::to_string(line_no_) + ": " + what);
  }

  // Next non-empty line, or false at end of file.
  bool next_line(std::string &line)
  {
    while (std::getline(in_, line)) {
      ++line_no_;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.find_first_not_of(" \t") != std::string::npos) return true;
    }
    return false;
  }

  std::istringstream data_line(const char *what)
  {
    std::string line;
    if (!next_line(line)) fail(std::string("unexpected end of file while reading ") + what);
    if (line[0] == '$') fail(std::string("section ended early (") + line + ") while reading " + what);
    return std::istringstream(line);
  }

  template <class T> T get(std::istringstream &s, const char *what)
  {
    T v;
    if (!(s >> v)) fail(std::string("expected ") + what);
    return v;
  }

  void expect_end(const std::string &section)
  {
    std::string line;
    if (!next_line(line)) fail("missing $End" + section);
    if (line.rfind("$End" + section, 0) != 0)
      fail("expected $End" + section + ", found '" + line + "' (count mismatch?)");
  }

  void skip_section(const std::string &section)
  {
    std::string line;
    const int   start = line_no_;
    while (next_line(line))
      if (line.rfind("$End" + section, 0) == 0) return;
    fail("section $" + section + " opened at line " + std::to_string(start) + " is not terminated (no $End" +
         section + ")");
  }

  TetMesh parse()
  {
    std::string line;
    double      version     = 0;
    bool        have_format = false, have_nodes = false, have_elements = false;
    while (next_line(line)) {
      if (line[0] != '$') fail("expected a section header, found '" + line + "'");
      const std::string section =
        line.substr(1, line.find_first_of(" \t") == std::string::npos ? std::string::npos
                                                                      : line.find_first_of(" \t") - 1);
      // gmsh files open with $MeshFormat: anything else (a misspelt header) is named here, not
      // skipped to the end of the file as an unknown section
      if (!have_format && section != "MeshFormat")
        fail("expected $MeshFormat as the first section, found '" + line + "'");
      if (section == "MeshFormat") {
        auto s              = data_line("$MeshFormat");
        version             = get<double>(s, "format version");
        const int file_type = get<int>(s, "file type");
        if (file_type != 0)
          fail(
            "binary .msh files are not supported: save the mesh as ASCII (gmsh -format msh22 or msh41, Mesh.Binary = 0)");
        if (version != 2.2 && version != 4.1)
          fail("unsupported .msh version " + std::to_string(version) + " (supported: 2.2 and 4.1 ASCII)");
        expect_end("MeshFormat");
        have_format = true;
      } else if (section == "Nodes") {
        if (!have_format) fail("$Nodes before $MeshFormat");
        version == 2.2 ? read_nodes_2() : read_nodes_4();
        expect_end("Nodes");
        have_nodes = true;
      } else if (section == "Elements") {
        if (!have_nodes) fail("$Elements before $Nodes");
        version == 2.2 ? read_elements_2() : read_elements_4();
        expect_end("Elements");
        have_elements = true;
      } else {
        skip_section(section);
      }
    }
    if (!have_format) fail("not a gmsh mesh: no $MeshFormat section");
    if (!have_nodes) fail("no $Nodes section");
    if (!have_elements) fail("no $Elements section");
    return build();
  }

private:
  void add_node(long long tag, double x, double y, double z)
  {
    if (!node_index_.emplace(tag, static_cast<int>(coords_.size() / 3)).second)
      fail("duplicate node tag " + std::to_string(tag));
    coords_.insert(coords_.end(), {x, y, z});
  }

  void read_nodes_2()
  {
    auto            s = data_line("node count");
    const long long n = get<long long>(s, "node count");
    if (n < 0) fail("negative node count");
    for (long long i = 0; i < n; ++i) {
      auto            t   = data_line("nodes (fewer than the count announced)");
      const long long tag = get<long long>(t, "node tag");
      const double    x = get<double>(t, "x"), y = get<double>(t, "y"), z = get<double>(t, "z");
      add_node(tag, x, y, z);
    }
  }

  // Format 4.1 sections ($Nodes, $Elements) share one shape: a header "blocks total ...", then per
  // entity block "dim tag <kind> count" and its lines. One walker checks the counts for both.
  template <class ReadBlock>
  void read_entity_blocks(const char *section, const char *items, const char *kind, ReadBlock read_block)
  {
    auto            s      = data_line((std::string(section) + " header").c_str());
    const long long blocks = get<long long>(s, "number of entity blocks");
    const long long n      = get<long long>(s, (std::string(items) + " count").c_str());
    long long       seen   = 0;
    for (long long b = 0; b < blocks; ++b) {
      auto t = data_line((std::string(items) + " block header").c_str());
      get<int>(t, "entity dimension");
      get<int>(t, "entity tag");
      const int       block_kind = get<int>(t, kind);
      const long long count      = get<long long>(t, (std::string(items) + "s in block").c_str());
      if (count < 0) fail(std::string("negative ") + items + " count in a block");
      read_block(block_kind, count);
      seen += count;
    }
    if (seen != n)
      fail(std::string(section) + " announces " + std::to_string(n) + " " + items + "s but its blocks hold " +
           std::to_string(seen));
  }

  void read_nodes_4()
  {
    // The parametric flag only adds coordinates at the end of a node line, which we do not read.
    read_entity_blocks("$Nodes", "node", "parametric flag", [&](int, long long count) {
      std::vector<long long> tags(count);
      for (auto &tag : tags) {
        auto u = data_line("node tags");
        tag    = get<long long>(u, "node tag");
      }
      for (long long tag : tags) {
        auto         u = data_line("node coordinates");
        const double x = get<double>(u, "x"), y = get<double>(u, "y"), z = get<double>(u, "z");
        add_node(tag, x, y, z);
      }
    });
  }

  void add_tet(int type, std::istringstream &s, long long element_tag)
  {
    const int n = type == 4 ? 4 : 10;
    if (order_ == 0) order_ = n == 4 ? 1 : 2;
    if ((order_ == 1) != (n == 4)) fail("the mesh mixes linear (4-node) and quadratic (10-node) tetrahedra");
    int v[10];
    for (int k = 0; k < n; ++k) {
      const long long tag = get<long long>(s, "element node tag");
      auto            it  = node_index_.find(tag);
      if (it == node_index_.end())
        fail("element " + std::to_string(element_tag) + " refers to undefined node " + std::to_string(tag));
      v[k] = it->second;
    }
    if (n == 10) std::swap(v[8], v[9]); // gmsh: 30 32 31 -> ours: 03 13 23 (same pair, flipped ends)
    tets_.insert(tets_.end(), v, v + n);
    tet_tags_.push_back(element_tag);
  }

  static bool is_tet(int type) { return type == 4 || type == 11; }

  void read_elements_2()
  {
    auto            s = data_line("element count");
    const long long n = get<long long>(s, "element count");
    for (long long i = 0; i < n; ++i) {
      auto            t    = data_line("elements (fewer than the count announced)");
      const long long tag  = get<long long>(t, "element tag");
      const int       type = get<int>(t, "element type");
      const int       ntag = get<int>(t, "tag count");
      for (int k = 0; k < ntag; ++k) get<long long>(t, "element tag value");
      if (is_tet(type)) add_tet(type, t, tag);
    }
  }

  void read_elements_4()
  {
    read_entity_blocks("$Elements", "element", "element type", [&](int type, long long count) {
      for (long long i = 0; i < count; ++i) {
        auto            u   = data_line("elements (fewer than the block announces)");
        const long long tag = get<long long>(u, "element tag");
        if (is_tet(type)) add_tet(type, u, tag);
      }
    });
  }

  TetMesh build()
  {
    if (tets_.empty())
      fail("the mesh has no tetrahedra (gmsh types 4 or 11); was it meshed in 3D (gmsh -3)?");
    TetMesh m;
    m.order = order_;
    std::vector<int> new_index(coords_.size() / 3, -1);
    for (int &v : tets_) {
      if (new_index[v] < 0) {
        new_index[v] = static_cast<int>(m.nodes.size() / 3);
        m.nodes.insert(m.nodes.end(), coords_.begin() + 3 * v, coords_.begin() + 3 * v + 3);
      }
      v = new_index[v];
    }
    m.elements = std::move(tets_);
    validate_mesh(m, name_, tet_tags_);
    return m;
  }

  std::istream                      &in_;
  std::string                        name_;
  int                                line_no_ = 0;
  int                                order_   = 0;
  std::vector<double>                coords_;
  std::unordered_map<long long, int> node_index_;
  std::vector<int>                   tets_;
  std::vector<long long>             tet_tags_; // the file's tag of each tetrahedron, for messages
};

} // namespace

TetMesh read_msh(std::istream &in, const std::string &name) { return MshParser(in, name).parse(); }

TetMesh read_msh_file(const std::string &path)
{
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open mesh file");
  return read_msh(in, path);
}

} // namespace physics
