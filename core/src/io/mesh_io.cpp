#include "strata/core/io/mesh_io.hpp"

#include <cctype>
#include <system_error>

#include "strata/core/common/error.hpp"
#include "strata/core/io/medit.hpp"
#include "strata/core/io/tetgen.hpp"
#include "strata/core/io/vtu.hpp"

namespace strata {

MeshFormat mesh_format_of(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  for (char& c : extension)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".msh") return MeshFormat::gmsh;
  if (extension == ".mesh") return MeshFormat::medit;
  if (extension == ".node" || extension == ".ele") return MeshFormat::tetgen;
  if (extension == ".vtu") return MeshFormat::vtu;
  throw InputError("'" + path.string() + "': unknown mesh extension '" + extension +
                   "' (expected .msh, .mesh, .node, .ele or .vtu)");
}

TetMesh read_tet_mesh(const std::filesystem::path& path) {
  const MeshFormat format = mesh_format_of(path);
  std::error_code error;
  if (format != MeshFormat::tetgen && !std::filesystem::exists(path, error))
    throw InputError("cannot open '" + path.string() + "': no such file");
  switch (format) {
    case MeshFormat::gmsh:
      return read_gmsh(path);
    case MeshFormat::medit:
      return read_medit(path);
    case MeshFormat::tetgen:
      return read_tetgen(path);
    case MeshFormat::vtu:
      return read_vtu(path);
  }
  throw InputError("'" + path.string() + "': unknown mesh format");
}

void write_tet_mesh(const std::filesystem::path& path, const TetMesh& mesh,
                    const MeshWriteOptions& options) {
  switch (mesh_format_of(path)) {
    case MeshFormat::gmsh:
      return write_gmsh(path, mesh, options.gmsh_version);
    case MeshFormat::medit:
      return write_medit(path, mesh);
    case MeshFormat::tetgen:
      return write_tetgen(path, mesh);
    case MeshFormat::vtu:
      return write_vtu(path, mesh);
  }
}

void convert_tet_mesh(const std::filesystem::path& in, const std::filesystem::path& out,
                      const MeshWriteOptions& options) {
  mesh_format_of(out);  // fail on a bad output name before reading
  write_tet_mesh(out, read_tet_mesh(in), options);
}

}  // namespace strata
