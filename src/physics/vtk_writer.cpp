#include "physics/vtk_writer.hpp"

#include <cstdio>
#include <filesystem>
#include <system_error>

namespace physics {

bool write_vtu(const std::string &path, const VtkScene &scene)
{
  std::FILE *f = std::fopen(path.c_str(), "w");
  if (!f) return false;
  const size_t npoints = scene.points.size() / 3;
  const size_t ncells  = scene.nodes_per_cell > 0 ? scene.connectivity.size() / scene.nodes_per_cell : 0;
  std::fprintf(
    f,
    "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n");
  std::fprintf(f, "<UnstructuredGrid><Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n", npoints,
               ncells);
  std::fprintf(f, "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
  for (size_t i = 0; i < npoints; ++i)
    std::fprintf(f, "%.9g %.9g %.9g\n", scene.points[3 * i], scene.points[3 * i + 1],
                 scene.points[3 * i + 2]);
  std::fprintf(
    f, "</DataArray></Points>\n<Cells>\n<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n");
  for (size_t c = 0; c < ncells; ++c) {
    for (int k = 0; k < scene.nodes_per_cell; ++k)
      std::fprintf(f, "%d ", scene.connectivity[c * scene.nodes_per_cell + k]);
    std::fprintf(f, "\n");
  }
  std::fprintf(f, "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n");
  for (size_t c = 0; c < ncells; ++c) std::fprintf(f, "%zu\n", (c + 1) * scene.nodes_per_cell);
  std::fprintf(f, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
  for (size_t c = 0; c < ncells; ++c) std::fprintf(f, "%d\n", static_cast<int>(scene.cell_type));
  std::fprintf(f, "</DataArray>\n</Cells>\n<PointData>\n");
  for (const VtkPointField &field : scene.point_fields) {
    std::fprintf(f, "<DataArray type=\"Float64\" Name=\"%s\" NumberOfComponents=\"%d\" format=\"ascii\">\n",
                 field.name.c_str(), field.components);
    for (size_t i = 0; i < npoints; ++i) {
      for (int k = 0; k < field.components; ++k)
        std::fprintf(f, "%.9g ", field.values[i * field.components + k]);
      std::fprintf(f, "\n");
    }
    std::fprintf(f, "</DataArray>\n");
  }
  std::fprintf(f, "</PointData>\n</Piece></UnstructuredGrid>\n</VTKFile>\n");
  return std::fclose(f) == 0;
}

bool write_pvd(const std::string &path, const std::vector<std::pair<std::string, double>> &frames)
{
  std::FILE *f = std::fopen(path.c_str(), "w");
  if (!f) return false;
  std::fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n");
  for (const auto &frame : frames)
    std::fprintf(f, "<DataSet timestep=\"%.9g\" file=\"%s\"/>\n", frame.second, frame.first.c_str());
  std::fprintf(f, "</Collection>\n</VTKFile>\n");
  return std::fclose(f) == 0;
}

void make_prefix_folder(const std::string &prefix)
{
  std::error_code             ec;
  const std::filesystem::path parent = std::filesystem::path(prefix).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
}

} // namespace physics
