// Internal entry points of the readers (src/io/), behind read_points and read_mesh: each takes
// an already opened MappedFile so the format can be sniffed once from its content.
#pragma once

#include <cstddef>
#include <functional>
#include <span>

#include "g2s/io.hpp"
#include "g2s/types.hpp"
#include "io/mapped_file.hpp"

namespace g2s::io {

// Receives the finite points of a cloud in file order, a run at a time (3 doubles per point);
// the span is valid during the call only.
using PointSink = std::function<void(std::span<const double> xyz)>;
// The readers' own sink: the run in the reader's vector, which the sink may take by swapping
// another vector in (the reader clears and refills whatever vector it then holds), so that a run
// handed to another thread needs no copy (read_ahead.cpp).
using RunSink = std::function<void(std::vector<double>& xyz)>;

// Largest run a streaming reader hands to a PointSink (1.5 MB of doubles: it stays in cache,
// and a small memory budget is not spent on it).
inline constexpr std::size_t kScanChunkPoints = std::size_t{1} << 16;

// Streams the points of a cloud (any format read_points reads, same checks, same messages,
// same numbering) to `sink` in bounded memory: the file is mapped lazily and consumed pages are
// released, so the resident set holds a window of the file and one run of points. This is the
// one reading path: read_points collects what it streams. Fills `report` as read_points does.
// Throws Error(bad_input) like read_points; runs already handed to the sink stay handed.
void scan_points(const std::filesystem::path& path, const PointSink& sink, ReadReport& report);
// The same with a RunSink.
void scan_runs(const std::filesystem::path& path, const RunSink& sink, ReadReport& report);
// The same, the reading done on a thread of its own a few runs ahead of `sink`, which is called
// on the calling thread with the same runs in the same order (read_ahead.cpp). In an arena of one
// thread it is scan_points. Up to three runs are held besides scan_points' own memory.
void scan_points_ahead(const std::filesystem::path& path, const PointSink& sink,
                       ReadReport& report);

// read_points and read_mesh on an opened file (point_reader.cpp, mesh_reader.cpp).
PointCloud read_points_from(const MappedFile& file, ReadReport& report);
IndexedMesh read_mesh_from(const MappedFile& file);

// Text XYZ/PTS/CSV points (xyz_reader.cpp). Fills report->format/points/non_finite. With a
// sink, the points go to it in order and the result is empty; without one, they are returned.
PointCloud read_xyz_points(const MappedFile& file, ReadReport& report, const RunSink* sink);

// ASPRS LAS 1.0-1.4 points, record formats 0-10 (las_reader.cpp): x, y, z of every record with
// the header's scale and offset applied in double. Fills report->format/declared/points/
// non_finite. With a sink, the points go to it in runs and consumed pages are released; without
// one, they are returned. LAZ (compressed LAS) and headers that contradict the file are
// Error(bad_input).
PointCloud read_las_points(const MappedFile& file, ReadReport& report, const RunSink* sink);

// True when the file starts with the LAS signature "LASF".
inline bool has_las_signature(const MappedFile& file) {
  return file.view().substr(0, 4) == "LASF";
}

// Binary or ASCII STL, welded (stl_reader.cpp); throws Error(bad_input) if it is neither.
IndexedMesh read_stl(const MappedFile& file);

// True when the file starts with the PLY magic line ("ply", maybe with trailing blanks; alone,
// a header cut short right after it).
inline bool has_ply_magic(const MappedFile& file) {
  const std::string_view v = file.view();
  return v.size() >= 3 && v.substr(0, 3) == "ply" &&
         (v.size() == 3 || v[3] == '\n' || v[3] == '\r' || v[3] == ' ' || v[3] == '\t');
}

}  // namespace g2s::io
