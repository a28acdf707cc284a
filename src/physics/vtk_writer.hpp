// ParaView .vtu (unstructured grid, ASCII) writer shared by every driver: a scene is points, cells
// of one VTK type, and named per-point fields (scalars or 3-vectors).
#pragma once
#include <string>
#include <vector>

namespace physics {

enum class VtkCellType : int {
  Vertex         = 1,
  Line           = 3,
  Triangle       = 5,
  Tetra          = 10,
  Hexahedron     = 12,
  QuadraticTetra = 24
};

struct VtkPointField {
  std::string         name;
  int                 components; // 1 or 3
  std::vector<double> values;     // components * number of points
};

struct VtkScene {
  std::vector<double>        points; // 3 per point
  VtkCellType                cell_type      = VtkCellType::Vertex;
  int                        nodes_per_cell = 1;
  std::vector<int>           connectivity; // nodes_per_cell per cell, VTK node order
  std::vector<VtkPointField> point_fields;
};

// Writes `path`; returns false (and writes nothing useful) when the file cannot be opened.
bool write_vtu(const std::string &path, const VtkScene &scene);

// Writes a ParaView collection (.pvd) that lists frames (file, time) so a series plays as animation.
bool write_pvd(const std::string &path, const std::vector<std::pair<std::string, double>> &frames);

// Makes the folder a frame prefix ("out/run/frame") lies in, with its parents, if missing. Best effort:
// a folder that cannot be made shows as the first frame's failure to write.
void make_prefix_folder(const std::string &prefix);

} // namespace physics
