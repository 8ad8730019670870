// read_mesh: sniffs the content (PLY magic, else binary STL by size, else ASCII STL by "solid")
// and returns an indexed mesh. PLY vertices are kept as they are (indices refer to them, so
// non-finite ones are not dropped); STL corners are welded by stl_reader.cpp.
#include "g2s/io.hpp"
#include "io/mapped_file.hpp"
#include "io/ply_format.hpp"
#include "io/readers.hpp"
#include "io/text_util.hpp"

namespace g2s {

IndexedMesh read_mesh(const std::filesystem::path& path) {
  const io::MappedFile file(path);
  if (file.size() == 0) {
    io::fail_input(file.name(), "file is empty (expected an STL or PLY mesh)");
  }
  if (io::has_ply_magic(file)) {
    const io::PlyHeader header = io::parse_ply_header(file);
    IndexedMesh mesh;
    io::PlyBodyRequest request;
    request.drop_non_finite = false;
    request.faces = &mesh.triangles;
    mesh.xyz = io::read_ply_body(file, header, request).xyz;
    return mesh;
  }
  return io::read_stl(file);
}

}  // namespace g2s
