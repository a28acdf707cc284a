#include "sim/geo_mesh.h"

#include "physics/msh_reader.hpp"
#include "physics/tet_mesh.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static PetscErrorCode EstimateGeoTets(MPI_Comm comm, const std::string &geo, double size, double *volume,
                                      double *tets);

static bool file_exists(const std::string &p)
{
  struct stat st;
  return stat(p.c_str(), &st) == 0;
}

// FNV-1a, 64 bits: a stable digest of the cache key (std::hash may differ between builds).
static unsigned long long Fnv1a64(const std::string &text)
{
  unsigned long long h = 1469598103934665603ull;
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  return h;
}

PetscErrorCode GeoMesh(MPI_Comm comm, std::string geo, double size, double max_tets, std::string *msh)
{
  PetscMPIInt rank;
  char        exe[PETSC_MAX_PATH_LEN] = "";
  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCheck(file_exists(geo), comm, PETSC_ERR_FILE_OPEN, "geometry file %s not found", geo.c_str());
  const ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
  std::string   dir = len > 0 ? std::string(exe, len) : std::string("./fem");
  dir               = dir.substr(0, dir.find_last_of('/')) + "/../meshes";
  std::string base  = geo.substr(geo.find_last_of('/') + 1);
  base              = base.substr(0, base.find_last_of('.'));
  char sz[64];
  std::snprintf(sz, sizeof sz, "%.17g", size);
  const std::string options =
    "-3 -format msh41 -v 1 -nt 1 " + (size > 0 ? "-clmax " + std::string(sz) + " " : std::string());
  // The cache entry is named by what decides the mesh: the .geo file's contents and the meshing options
  // (the base name alone would hand an edited file, or another folder's file of that name, a stale mesh).
  // A .geo that includes other files (Merge, Include) is keyed on its own text only.
  int  failed  = 0;
  char key[17] = "";
  if (!rank) {
    std::ifstream in(geo, std::ios::binary);
    std::string   text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    failed = !in.good() && !in.eof();
    std::snprintf(key, sizeof key, "%016llx", (unsigned long long)Fnv1a64(text + '\0' + options));
  }
  PetscCallMPI(MPI_Bcast(key, sizeof key, MPI_CHAR, 0, comm));
  *msh     = dir + "/" + base + "_" + key + ".msh";
  int make = !rank && !failed && !file_exists(*msh);
  PetscCallMPI(MPI_Bcast(&make, 1, MPI_INT, 0, comm));
  if (make && size > 0 && max_tets > 0) {
    double volume, tets;
    PetscCall(EstimateGeoTets(comm, geo, size, &volume, &tets));
    PetscCheck(tets <= max_tets, comm, PETSC_ERR_ARG_OUTOFRANGE,
               "-mesh_size %g would mesh %s (%.4g m^3) into about %.3g tetrahedra, over -mesh_max_elements "
               "%.3g: choose a larger -mesh_size (%.3g gives about that many)",
               size, geo.c_str(), volume, tets, max_tets, size * std::cbrt(tets / max_tets));
  }
  char why[512] = ""; // gmsh's own words, or what the reader found wrong with what gmsh wrote
  if (make) {
    mkdir(dir.c_str(), 0755);
    const std::string tmp = *msh + ".tmp." + std::to_string(getpid()) + ".msh", log = tmp + ".log";
    std::string       cmd    = "gmsh " + options + "'" + geo + "' -o '" + tmp + "' > '" + log + "' 2>&1";
    const int         status = std::system(cmd.c_str());
    if (status != 0) {
      failed = 1;
      std::ifstream in(log);
      std::string   line, last;
      while (std::getline(in, line)) // gmsh's first error says what is wrong with the file
        if (line.find("Error") != std::string::npos && !why[0])
          std::snprintf(why, sizeof why, "%s", line.c_str());
        else if (!line.empty()) last = line;
      if (!why[0]) std::snprintf(why, sizeof why, "%s", last.empty() ? "gmsh printed nothing" : last.c_str());
      if (WIFEXITED(status) && WEXITSTATUS(status) == 127) // the shell's "command not found"
        std::snprintf(why, sizeof why, "gmsh not found (scripts/setup installs it)");
    } else {
      try { // a .geo gmsh meshes without complaint may still give no tetrahedra (an empty file does)
        physics::read_msh_file(tmp);
      } catch (const std::exception &e) {
        failed = 1;
        std::snprintf(why, sizeof why, "gmsh made no usable mesh of it: %s", e.what());
      }
    }
    if (!failed && std::rename(tmp.c_str(), msh->c_str()) != 0) {
      failed = 1;
      std::snprintf(why, sizeof why, "cannot put the mesh in the cache folder %s", dir.c_str());
    }
    if (failed) std::remove(tmp.c_str()); // what gmsh left of a failed mesh stays out of the cache
    std::remove(log.c_str());
  }
  PetscCallMPI(MPI_Bcast(&failed, 1, MPI_INT, 0, comm));
  PetscCallMPI(MPI_Bcast(why, sizeof why, MPI_CHAR, 0, comm));
  PetscCheck(!failed, comm, PETSC_ERR_LIB, "gmsh could not mesh %s: %s", geo.c_str(),
             why[0] ? why : "cannot read it");
  PetscFunctionReturn(0);
}

// About how many tetrahedra gmsh makes of `geo` at -clmax `size`: the body's volume (from the file's own,
// coarse mesh, cached like any other) over that of a regular tetrahedron of edge `size`. gmsh's
// tetrahedra are a little larger on average: armadillo.geo at 0.0175 is estimated at 80,000 and meshed
// into 60,448, bunny.geo at 0.03 at 5,450 and 4,471. Without the bound a tiny size ran gmsh for hours,
// printing nothing.
static PetscErrorCode EstimateGeoTets(MPI_Comm comm, const std::string &geo, double size, double *volume,
                                      double *tets)
{
  std::string coarse;
  PetscFunctionBegin;
  PetscCall(GeoMesh(comm, geo, 0, 0, &coarse));
  std::string error;
  *volume = 0;
  try {
    const physics::TetMesh mesh = physics::read_msh_file(coarse);
    for (int e = 0; e < mesh.element_count(); ++e)
      *volume += std::fabs(physics::element_signed_volume(mesh, mesh.nodes.data(), e));
  } catch (const std::exception &ex) {
    error = ex.what();
  }
  PetscCheck(error.empty(), comm, PETSC_ERR_FILE_UNEXPECTED, "%s: its coarse mesh: %s", geo.c_str(),
             error.c_str());
  *tets = *volume / (size * size * size / (6 * std::sqrt(2.0)));
  PetscFunctionReturn(0);
}
