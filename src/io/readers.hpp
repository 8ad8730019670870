// Internal entry points of the readers (src/io/), behind read_points and read_mesh: each takes
// an already opened MappedFile so the format can be sniffed once from its content.
#pragma once

#include "g2s/io.hpp"
#include "g2s/types.hpp"
#include "io/mapped_file.hpp"

namespace g2s::io {

// read_points and read_mesh on an opened file (point_reader.cpp, mesh_reader.cpp).
PointCloud read_points_from(const MappedFile& file, ReadReport& report);
IndexedMesh read_mesh_from(const MappedFile& file);

// Text XYZ/PTS/CSV points (xyz_reader.cpp). Fills report->format/points/non_finite.
PointCloud read_xyz_points(const MappedFile& file, ReadReport& report);

// Binary or ASCII STL, welded (stl_reader.cpp); throws Error(bad_input) if it is neither.
IndexedMesh read_stl(const MappedFile& file);

// True when the file starts with the PLY magic line ("ply", maybe with trailing blanks).
inline bool has_ply_magic(const MappedFile& file) {
  const std::string_view v = file.view();
  return v.size() >= 4 && v.substr(0, 3) == "ply" &&
         (v[3] == '\n' || v[3] == '\r' || v[3] == ' ' || v[3] == '\t');
}

}  // namespace g2s::io
