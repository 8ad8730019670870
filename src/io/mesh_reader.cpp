// read_mesh: sniffs the content (PLY magic, else binary STL by size, else ASCII STL by "solid")
// and returns an indexed mesh. PLY vertices are kept as they are (indices refer to them, so
// non-finite ones are not dropped); STL corners are welded by stl_reader.cpp.
#include "g2s/io.hpp"
#include "io/mapped_file.hpp"
#include "io/ply_format.hpp"
#include "io/readers.hpp"
#include "io/text_util.hpp"

namespace g2s {
namespace io {

IndexedMesh read_mesh_from(const MappedFile& file) {
  if (file.size() == 0) fail_input(file.name(), "file is empty (expected an STL or PLY mesh)");
  if (has_ply_magic(file)) {
    const PlyHeader header = parse_ply_header(file);
    IndexedMesh mesh;
    PlyBodyRequest request;
    request.drop_non_finite = false;
    request.faces = &mesh.triangles;
    mesh.xyz = read_ply_body(file, header, request).xyz;
    return mesh;
  }
  return read_stl(file);
}

}  // namespace io

IndexedMesh read_mesh(const std::filesystem::path& path) {
  return io::read_mesh_from(io::MappedFile(path));
}

}  // namespace g2s
