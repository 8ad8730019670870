// MeshStreamWriter: the tiled pipeline's output stage. Triangles arrive as the stitcher finishes
// them but their orientation is known only at the end.
// - Binary STL: each facet goes straight into the target's temporary as it comes, facing as its
//   group does so far, and the runs of one group go to a small spill file; at the end only the
//   facets of flipped groups are rewritten in place, window by window in parallel.
// - ASCII STL and PLY (variable-length text; vertices before faces): triangles go to a spill file
//   beside the target, then one sequential pass writes the real file with each group's flip
//   applied.
// The spills are temporaries, removed however the run ends. Memory stays a few buffers whatever
// the mesh.
#include <fcntl.h>
#include <fmt/core.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "io/le_bytes.hpp"
#include "io/stl_record.hpp"
#include "io/write_behind.hpp"

namespace g2s {
namespace {

constexpr std::size_t kBufferSize = 1u << 20;

// An append-only temporary file read back once from the start.
class SpillFile {
 public:
  SpillFile(const std::filesystem::path& target, const char* kind)
      : target_(target), path_(hidden_beside(target, fmt::format("{}-{}", kind, ::getpid()))) {
    fd_ = ::open(path_.path().c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd_ < 0) fail("cannot create a spill file");
    buffer_.reserve(kBufferSize);
    behind_ = std::make_unique<WriteBehind>(fd_, kBufferSize);
  }
  ~SpillFile() {
    behind_.reset();  // its thread may be writing to fd_
    if (fd_ >= 0) ::close(fd_);
  }
  SpillFile(const SpillFile&) = delete;
  SpillFile& operator=(const SpillFile&) = delete;

  void append(const void* data, std::size_t bytes) {
    if (buffer_.size() + bytes > kBufferSize) flush();
    const auto* p = static_cast<const char*>(data);
    buffer_.insert(buffer_.end(), p, p + bytes);
  }

  // Calls each(record) for every `record_bytes` record appended, in order.
  template <typename Each>
  void read_back(std::size_t record_bytes, Each each) {
    flush();
    if (const int err = behind_->wait(); err != 0) fail("cannot write the spill file", err);
    std::vector<char> chunk(kBufferSize / record_bytes * record_bytes);
    for (std::uint64_t offset = 0; offset < size_;) {
      const auto want =
          static_cast<std::size_t>(std::min<std::uint64_t>(chunk.size(), size_ - offset));
      std::size_t got = 0;
      while (got < want) {
        const ssize_t n =
            ::pread(fd_, chunk.data() + got, want - got, static_cast<off_t>(offset + got));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) fail("cannot read back the spill file");
        got += static_cast<std::size_t>(n);
      }
      for (std::size_t k = 0; k < want; k += record_bytes) each(chunk.data() + k);
      offset += want;
    }
  }
  double write_cpu_seconds() const { return behind_->cpu_seconds(); }

 private:
  // The buffer goes to the file on the write-behind thread (the stitcher fills the spills).
  void flush() {
    const std::size_t bytes = buffer_.size();
    if (bytes == 0) return;
    if (const int err = behind_->submit(buffer_, size_); err != 0) {
      fail("cannot write the spill file", err);
    }
    size_ += bytes;
  }
  [[noreturn]] void fail(const char* what, int err = errno) const {
    throw Error(Exit::write_failed,
                fmt::format("{}: {}: {}", target_.string(), what, std::strerror(err)));
  }

  std::filesystem::path target_;
  TemporaryPath path_;
  int fd_ = -1;
  std::vector<char> buffer_;
  std::uint64_t size_ = 0;  // bytes handed to the write-behind thread
  std::unique_ptr<WriteBehind> behind_;
};

bool survives_float(double v) {
  return static_cast<double>(static_cast<float>(v)) == v;
}

// Facets of a binary STL read, flipped where needed and written back at a time (800 KB), and
// windows gathered before they are rewritten in parallel.
constexpr std::uint64_t kWindowFacets = 1u << 14;
constexpr std::uint64_t kBatchWindows = 16;

// Rewrites the facets of `ranges` ([lo, hi), sorted) that lie in the window starting at facet
// `window` of a flushed binary STL with corners b and c swapped, as if written flipped.
void flip_facets(AtomicFile& stl, std::span<const std::array<std::uint64_t, 2>> ranges,
                 std::uint64_t window) {
  std::vector<char> bytes;
  const auto start = std::partition_point(ranges.begin(), ranges.end(),
                                          [&](const auto& r) { return r[1] <= window; });
  for (auto range = start; range != ranges.end() && (*range)[0] < window + kWindowFacets; ++range) {
    const std::uint64_t first = std::max((*range)[0], window);
    const std::uint64_t last = std::min((*range)[1], window + kWindowFacets);
    bytes.resize((last - first) * kStlRecordBytes);
    const std::uint64_t offset = kStlHeaderBytes + first * kStlRecordBytes;
    stl.read_at(offset, bytes.data(), bytes.size());
    for (std::size_t r = 0; r < bytes.size(); r += kStlRecordBytes) {
      float f[9];
      std::memcpy(f, bytes.data() + r + 12, sizeof f);
      double c[9];
      for (int k = 0; k < 9; ++k) c[k] = f[k];
      stl_record(c, c + 6, c + 3, bytes.data() + r);
    }
    stl.write_at(offset, bytes.data(), bytes.size());
  }
}

}  // namespace

struct MeshStreamWriter::Impl {
  Impl(const std::filesystem::path& t, MeshFormat f) : target(t), format(f) {
    if (format == MeshFormat::stl_binary) {
      stl = std::make_unique<AtomicFile>(t);
      stl->write_behind();  // the stitcher fills the facets; another thread writes them
      char header[kStlHeaderBytes] = {};
      const char text[] = "binary STL written by g2s";
      std::memcpy(header, text, sizeof text - 1);
      std::memset(header + sizeof text - 1, ' ', 80 - (sizeof text - 1));
      stl->write(header, sizeof header);  // the count (bytes 80..83) is patched by finish()
      runs = std::make_unique<SpillFile>(t, "groups");
      return;
    }
    triangles = std::make_unique<SpillFile>(t, "triangles");
    if (format == MeshFormat::ply_binary) vertices = std::make_unique<SpillFile>(t, "vertices");
  }
  template <typename Flipped>
  void finish_binary_stl(const Flipped& flipped);
  // Binary STL: one facet, facing as its group does so far.
  void add_facet(const char record[kStlRecordBytes], std::uint32_t group) {
    if (triangle_count >= std::numeric_limits<std::uint32_t>::max()) {
      throw Error(Exit::write_failed,
                  fmt::format("{}: more than {} triangles do not fit in a binary STL",
                              target.string(), std::numeric_limits<std::uint32_t>::max()));
    }
    stl->write(record, kStlRecordBytes);
    if (run_count > 0 && run_group != group) end_run();
    run_group = group;
    ++run_count;
    ++triangle_count;
  }
  void end_run() {
    if (run_count == 0) return;
    const std::uint32_t record[2] = {run_group, run_count};
    runs->append(record, sizeof record);
    run_count = 0;
  }
  std::filesystem::path target;
  MeshFormat format;
  std::unique_ptr<AtomicFile> stl;  // binary STL: the target, facets as they come
  std::unique_ptr<SpillFile> runs;  // binary STL: (group, facets) per run of one group
  std::uint32_t run_group = 0;
  std::uint32_t run_count = 0;
  std::unique_ptr<SpillFile> triangles;  // ASCII STL: group, 9 floats; PLY: group, 3 numbers
  std::unique_ptr<SpillFile> vertices;   // PLY: 3 doubles per vertex
  std::uint64_t vertex_count = 0;
  std::uint64_t triangle_count = 0;
  bool as_float = true;
  double largest = 0.0;
  double worst = 0.0;
};

// The facets of flipped groups, gathered from the runs a batch of windows at a time; each window
// is read, flipped and written back by one task.
template <typename Flipped>
void MeshStreamWriter::Impl::finish_binary_stl(const Flipped& flipped) {
  end_run();
  stl->flush();
  std::vector<std::array<std::uint64_t, 2>> ranges;  // flipped facets [lo, hi) in the batch
  std::uint64_t batch = 0;                           // first facet of the batch
  constexpr std::uint64_t kBatchFacets = kBatchWindows * kWindowFacets;
  auto rewrite_batch = [&] {
    if (!ranges.empty()) {
      tbb::parallel_for(std::uint64_t{0}, kBatchWindows, [&](std::uint64_t w) {
        flip_facets(*stl, ranges, batch + w * kWindowFacets);
      });
    }
    ranges.clear();
    batch += kBatchFacets;
  };
  std::uint64_t facet = 0;
  runs->read_back(8, [&](const char* record) {
    std::uint32_t run[2];
    std::memcpy(run, record, sizeof run);
    std::uint64_t lo = facet;
    facet += run[1];
    if (!flipped(run[0])) return;
    while (lo < facet) {
      // rewrite_batch() advances `batch` (a member the check cannot see it change).
      while (lo >= batch + kBatchFacets) rewrite_batch();  // NOLINT(bugprone-infinite-loop)
      const std::uint64_t hi = std::min(facet, batch + kBatchFacets);
      if (!ranges.empty() && ranges.back()[1] == lo) {
        ranges.back()[1] = hi;
      } else {
        ranges.push_back({lo, hi});
      }
      lo = hi;
    }
  });
  rewrite_batch();
  char count[4];
  io::put_le(count, static_cast<std::uint32_t>(triangle_count));
  stl->write_at(80, count, sizeof count);
  stl->commit();
}

MeshStreamWriter::MeshStreamWriter(const std::filesystem::path& target, MeshFormat format)
    : impl_(std::make_unique<Impl>(target, format)) {}

MeshStreamWriter::~MeshStreamWriter() = default;

double MeshStreamWriter::write_cpu_seconds() const {
  const Impl& m = *impl_;
  double seconds = m.stl ? m.stl->write_behind_cpu_seconds() : 0.0;
  for (const auto* spill : {m.runs.get(), m.triangles.get(), m.vertices.get()}) {
    if (spill) seconds += spill->write_cpu_seconds();
  }
  return seconds;
}

void MeshStreamWriter::vertex(Index, const double xyz[3]) {
  Impl& m = *impl_;
  ++m.vertex_count;
  for (int k = 0; k < 3; ++k) {
    if (m.format != MeshFormat::ply_binary) require_stl_coordinate(m.target, xyz[k]);
    m.largest = std::max(m.largest, std::abs(xyz[k]));
    m.worst = std::max(m.worst, std::abs(xyz[k] - static_cast<double>(static_cast<float>(xyz[k]))));
    m.as_float = m.as_float && survives_float(xyz[k]);
  }
  if (m.vertices) m.vertices->append(xyz, 3 * sizeof(double));
}

void MeshStreamWriter::triangle(const Triangle& corners, const std::array<const double*, 3>& xyz,
                                std::uint32_t group) {
  Impl& m = *impl_;
  if (m.format == MeshFormat::stl_binary) {
    char record[kStlRecordBytes];
    stl_record(xyz[0], xyz[1], xyz[2], record);
    m.add_facet(record, group);
    return;
  }
  ++m.triangle_count;
  if (m.format == MeshFormat::ply_binary) {
    const std::uint32_t record[4] = {group, corners[0], corners[1], corners[2]};
    m.triangles->append(record, sizeof record);
    return;
  }
  struct {
    std::uint32_t group;
    float xyz[9];
  } record{group, {}};
  for (int c = 0; c < 3; ++c) {
    for (int k = 0; k < 3; ++k) record.xyz[3 * c + k] = static_cast<float>(xyz[c][k]);
  }
  m.triangles->append(&record, sizeof record);
}

namespace {
// A block's binary STL facet normals, worked out ahead.
struct StlNormals final : SinkBlockWork {
  std::vector<float> normals;  // 3 per triangle
};
}  // namespace

std::unique_ptr<SinkBlockWork> MeshStreamWriter::prepare(const SinkBlock& block) const {
  if (impl_->format != MeshFormat::stl_binary) return nullptr;
  auto work = std::make_unique<StlNormals>();
  work->normals.resize(3 * block.triangles.size());
  for (std::size_t k = 0; k < block.triangles.size(); ++k) {
    const Triangle& t = block.triangles[k];
    stl_normal(&block.xyz[3 * std::size_t{t[0]}], &block.xyz[3 * std::size_t{t[1]}],
               &block.xyz[3 * std::size_t{t[2]}], &work->normals[3 * k]);
  }
  return work;
}

void MeshStreamWriter::block(const SinkBlock& block, std::uint32_t first_vertex,
                             std::uint32_t first_group, std::unique_ptr<SinkBlockWork> work) {
  if (!work) {
    MeshSink::block(block, first_vertex, first_group, nullptr);
    return;
  }
  // Only prepare() makes this sink's work.
  const std::vector<float>& normals = static_cast<const StlNormals&>(*work).normals;
  Impl& m = *impl_;
  for (std::size_t v = 0; v < block.ids.size(); ++v) vertex(block.ids[v], &block.xyz[3 * v]);
  for (std::size_t k = 0; k < block.triangles.size(); ++k) {
    const Triangle& t = block.triangles[k];
    char record[kStlRecordBytes];
    stl_record(&block.xyz[3 * std::size_t{t[0]}], &block.xyz[3 * std::size_t{t[1]}],
               &block.xyz[3 * std::size_t{t[2]}], &normals[3 * k], record);
    m.add_facet(record, first_group + block.group[k]);
  }
}

void MeshStreamWriter::finish(std::span<const std::uint8_t> flip) {
  Impl& m = *impl_;
  if (m.triangle_count == 0) return;  // no file: the caller says why there is no surface
  auto flipped = [&](std::uint32_t group) {
    if (group >= flip.size()) throw Error(Exit::failure, "mesh writer: unknown orientation group");
    return flip[group] != 0;
  };
  if (m.format == MeshFormat::stl_binary) {
    m.finish_binary_stl(flipped);
    return;
  }
  if (m.format == MeshFormat::stl_ascii) {
    StlWriter writer(m.target, true);
    m.triangles->read_back(40, [&](const char* record) {
      std::uint32_t group = 0;
      float f[9];
      std::memcpy(&group, record, 4);
      std::memcpy(f, record + 4, sizeof f);
      double c[9];
      for (int k = 0; k < 9; ++k) c[k] = f[k];
      if (flipped(group)) {
        writer.add(c, c + 6, c + 3);
      } else {
        writer.add(c, c + 3, c + 6);
      }
    });
    writer.finish();
    return;
  }
  AtomicFile file(m.target);
  const char* type = m.as_float ? "float" : "double";
  const std::string header = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment written by g2s\nelement vertex {}\n"
      "property {} x\nproperty {} y\nproperty {} z\nelement face {}\n"
      "property list uchar uint vertex_indices\nend_header\n",
      m.vertex_count, type, type, type, m.triangle_count);
  file.write(header.data(), header.size());
  char out[24];
  m.vertices->read_back(3 * sizeof(double), [&](const char* record) {
    char* p = out;
    for (int k = 0; k < 3; ++k) {
      double c = 0;
      std::memcpy(&c, record + 8 * k, 8);
      p = m.as_float ? io::put_le(p, static_cast<float>(c)) : io::put_le(p, c);
    }
    file.write(out, static_cast<std::size_t>(p - out));
  });
  m.triangles->read_back(16, [&](const char* record) {
    std::uint32_t r[4];
    std::memcpy(r, record, sizeof r);
    if (flipped(r[0])) std::swap(r[2], r[3]);
    char* p = io::put_le(out, std::uint8_t{3});
    for (int k = 1; k < 4; ++k) p = io::put_le(p, r[k]);
    file.write(out, static_cast<std::size_t>(p - out));
  });
  file.commit();
}

std::uint64_t MeshStreamWriter::triangles() const {
  return impl_->triangle_count;
}

double MeshStreamWriter::largest_coordinate() const {
  return impl_->largest;
}

double MeshStreamWriter::float_rounding() const {
  return impl_->worst;
}

}  // namespace g2s
