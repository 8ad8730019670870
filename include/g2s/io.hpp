// Readers and writers (src/io/). Every format error throws g2s::Error(Exit::bad_input) with a
// message naming the file, the place (line or byte offset) and what was expected; every write
// failure throws g2s::Error(Exit::write_failed) and leaves no file at the target path.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "g2s/mesh_sink.hpp"
#include "g2s/types.hpp"

namespace g2s {

// What a point reader saw, for the CLI summary and the tests.
struct ReadReport {
  std::string format;            // "ply-binary-le", "ply-binary-be", "ply-ascii", "xyz",
                                 // "las-1.4-format6"
  std::uint64_t declared = 0;    // points the header declares (0 for XYZ)
  std::uint64_t points = 0;      // finite points returned
  std::uint64_t non_finite = 0;  // points dropped for a NaN or Inf coordinate
  // Bytes after the body a PLY's header declares (more data than it declares, or trailing
  // garbage), ignored; blanks after ASCII rows do not count.
  std::uint64_t ignored_bytes = 0;
};

// Reads the points of a cloud. PLY (ascii, binary little and big endian; the vertex element's
// x, y, z as float or double at any position; other properties and elements skipped), ASPRS LAS
// 1.0-1.4 (point formats 0-10; x, y, z with the header's scale and offset applied in double;
// LAZ is Error(bad_input) saying how to decompress it; docs/las.md) or text XYZ/PTS/TXT/CSV
// (space, tab or comma separated; extra columns ignored; '#' and '//' comment lines; a PTS count
// line is skipped). The format is chosen by content (a "LASF" signature, a "ply" magic line),
// not by the file name; another file holding binary bytes is an error. ASCII PLY rows are one
// per line. A PLY body is read as far as its header declares (the elements after the vertices
// walked without being kept): bytes after the last element are ignored (counted in
// report->ignored_bytes), a body shorter than declared anywhere is an error. NaN/Inf points are
// dropped and counted. Duplicates are kept (the mesher merges them). Zero points is not an error
// here (an empty cloud is returned; the caller decides). Throws Error(bad_input) for a missing,
// unreadable or malformed file: "<file>: line N: ..." (text, PLY header) or "<file>: byte N: ..."
// (binary body).
PointCloud read_points(const std::filesystem::path& path, ReadReport* report = nullptr);

// Reads a triangle mesh: binary STL (recognised by its size, 84 + 50 * count, not by a "solid"
// header), ASCII STL, both welded by exact float coordinate equality (-0 == +0) with vertices
// numbered in order of first use; or PLY with a vertex and a face element (a vertex_indices or
// vertex_index list of any integer type; polygons are fanned from their first corner, faces with
// fewer than 3 corners skipped). PLY vertices are kept as they are, non-finite ones included.
// Triangle order is the file's. Throws Error(bad_input) like read_points.
IndexedMesh read_mesh(const std::filesystem::path& path);

enum class MeshFormat { stl_binary, stl_ascii, ply_binary };

// The format for an output path: .ply -> ply_binary, otherwise STL (ascii when asked).
MeshFormat mesh_format_for(const std::filesystem::path& path, bool ascii_stl);

// The signals that end a run as interrupted: SIGINT (Ctrl-C), SIGTERM (kill, a scheduler's
// cancel), SIGHUP (the terminal or ssh session closed) and SIGQUIT (Ctrl-\).
std::span<const int> interrupt_signals();

// Makes the interrupt signals remove every open AtomicFile's temporary, print a message and exit
// with Exit::interrupted (130). For programs; a library user may keep its own handlers.
void install_interrupt_cleanup();

// The path of a hidden file beside `target` for one of its run's temporaries:
// ".<target's name>.<tag>" in the same folder, the name cut short where the whole would pass the
// file system's 255-byte limit on a name (so a legal target name never makes its temporary's
// illegal). `tag` tells the temporaries apart (a kind, the process id, a counter).
std::filesystem::path hidden_beside(const std::filesystem::path& target, std::string_view tag);

// A file that exists only while a run needs it (the temporary tile store of `g2s mesh`):
// removed when destroyed, and by the interrupt handler.
class TemporaryPath {
 public:
  explicit TemporaryPath(std::filesystem::path path);
  ~TemporaryPath();
  TemporaryPath(const TemporaryPath&) = delete;
  TemporaryPath& operator=(const TemporaryPath&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  int registry_slot_ = -1;
};

// A file that appears at its target path only when complete: writes go through a 1 MiB buffer
// to a temporary ".NAME.tmp-<pid>-<n>" in the same folder; write_at patches bytes already
// written (flushed or still buffered); commit() flushes, closes (checking the result; no fsync)
// and renames over the target; destroying an uncommitted file removes the temporary. All OS
// failures throw Error(write_failed, "<target>: <what>: <strerror>"), e.g. missing or read-only
// folder, disk full (ENOSPC) or file size limit (EFBIG). A symbolic link is written through (the
// file it names is replaced, the link stays); an existing target that is not a regular file
// (device, FIFO, socket) throws Error(write_failed) and is left alone. After write_behind(),
// full buffers are written on a thread of their own while the caller fills the next; a failed
// write then throws at the next call that hands a buffer over, or at flush or commit.
class WriteBehind;
class AtomicFile {
 public:
  explicit AtomicFile(const std::filesystem::path& target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  void write(const void* data, std::size_t bytes);                           // buffered
  void write_at(std::uint64_t offset, const void* data, std::size_t bytes);  // patch written bytes
  std::uint64_t size() const;                                                // bytes written so far
  // Hands the buffer to the OS. After it, until the next write(), read_at and write_at touch
  // only the file and may run from several threads at once on disjoint ranges.
  void flush();
  void read_at(std::uint64_t offset, void* data, std::size_t bytes) const;  // flushed bytes only
  void commit();
  void write_behind();
  double write_behind_cpu_seconds() const;  // the writing thread's so far (0 without it)
  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& temporary() const { return temporary_; }

 private:
  void flush_buffer();
  void write_out(const char* p, std::size_t bytes);  // at written_, on this thread
  void wait_behind() const;                          // every buffer handed over is written
  std::filesystem::path target_;
  std::filesystem::path destination_;  // target_ with symbolic links followed
  std::filesystem::path temporary_;
  int fd_ = -1;
  std::vector<char> buffer_;
  std::uint64_t written_ = 0;  // bytes handed to the OS
  bool committed_ = false;
  int registry_slot_ = -1;  // in the interrupt handler's list of temporaries
  std::unique_ptr<WriteBehind> behind_;
  double behind_cpu_ = 0;  // the writing thread's CPU seconds, once it is gone
};

// Streams triangles to STL (binary or ASCII) as they come: memory stays constant whatever the
// count. Binary STL's triangle count is patched into the header by finish(). Facet normals are
// the normalised cross product of the float corners (zero for a degenerate facet). ASCII STL
// ("solid g2s" ... "endsolid g2s") prints the shortest text that reads back as the same float.
// Destroyed without finish() (an exception went by), it leaves no file.
class StlWriter {
 public:
  StlWriter(const std::filesystem::path& target, bool ascii);
  void add(const double a[3], const double b[3], const double c[3]);
  void finish();  // completes the file and renames it into place
  std::uint64_t triangles() const { return count_; }

 private:
  AtomicFile file_;
  bool ascii_;
  std::uint64_t count_ = 0;
};

// Writes a mesh whose triangles index into xyz (3 doubles per point, point_count points) in the
// given format. PLY output is indexed: only the points the triangles use are written, in order
// of first use, as float (double when a coordinate does not round-trip through float), faces as
// "list uchar uint vertex_indices". A triangle index past the points is Error(failure) (a bug),
// thrown before anything is written.
void write_mesh(const std::filesystem::path& target, std::span<const double> xyz,
                std::span<const Triangle> triangles, MeshFormat format);

// The tiled pipeline's writer: a MeshSink that spills triangles to a temporary beside the target
// as they come, and at finish() writes the target in `format` with the groups' flips applied,
// atomically (as write_mesh would: PLY indexed, float unless a coordinate would not survive).
// Disk: binary STL is written in place as triangles come, with 8 bytes per run of one group
// beside it; ASCII STL spills 40 bytes a triangle, PLY 16 a triangle and 24 a vertex, and the
// spill and the output exist together at the end. With no triangle, or destroyed unfinished, it
// leaves no file.
class MeshStreamWriter final : public MeshSink {
 public:
  MeshStreamWriter(const std::filesystem::path& target, MeshFormat format);
  ~MeshStreamWriter() override;
  void vertex(Index id, const double xyz[3]) override;
  void triangle(const Triangle& corners, const std::array<const double*, 3>& xyz,
                std::uint32_t group) override;
  // Binary STL: a block's facet normals are worked out ahead (12 bytes a triangle).
  std::unique_ptr<SinkBlockWork> prepare(const SinkBlock& block) const override;
  void block(const SinkBlock& block, std::uint32_t first_vertex, std::uint32_t first_group,
             std::unique_ptr<SinkBlockWork> work) override;
  void finish(std::span<const std::uint8_t> flip) override;
  std::uint64_t triangles() const;
  // For the STL rounding warning: the largest |coordinate| of the vertices, and the most
  // rounding to float moves one.
  double largest_coordinate() const;
  double float_rounding() const;
  // CPU seconds of the threads that wrote the binary STL's facets, or the other formats'
  // spills, beside the caller (finish() writes the rest).
  double write_cpu_seconds() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Writes points as binary little-endian PLY with float x, y, z, streamed: begin with the
// count, add points, finish() checks the count and renames into place. A count mismatch throws
// Error(failure) from finish() and leaves no file.
class PlyPointWriter {
 public:
  PlyPointWriter(const std::filesystem::path& target, std::uint64_t count);
  void add(float x, float y, float z);
  void finish();

 private:
  AtomicFile file_;
  std::uint64_t expected_;
  std::uint64_t count_ = 0;
};

}  // namespace g2s
