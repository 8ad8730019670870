// Read-only view of a whole input file for the readers: mmap for regular files (no copy, the
// page cache does the work), a read() loop for /proc-like files (size 0), or a copy of bytes
// already in memory (the fuzz targets: an exactly sized heap buffer, so a read past the end is
// caught by AddressSanitizer, which an mmap's page padding would hide). Opening problems
// (missing, directory, device, FIFO, socket, permission) throw Error(bad_input) naming the file. A
// streaming reader maps lazily and releases the pages it has consumed, so resident memory stays at
// a window however large the file.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace g2s::io {

// A regular file opened read-only, as every reader opens its input: a missing file, a directory,
// a device, FIFO or socket (which may never end), or a file it may not read throws
// Error(bad_input) naming it. MappedFile maps one; the tile store reads its blocks with read_at.
class InputFile {
 public:
  explicit InputFile(const std::filesystem::path& path);
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  int fd() const { return fd_; }
  std::uint64_t size() const { return size_; }  // as stat gave it when opened
  const std::string& name() const { return name_; }

  // Reads [offset, offset + bytes) into `data`; throws Error(bad_input) if the file ends first
  // (it shrank since it was opened) or the read fails.
  void read_at(std::uint64_t offset, void* data, std::size_t bytes) const;

 private:
  std::string name_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

// whole: every page is read in at once (fastest when the caller keeps the whole cloud anyway).
// stream: pages are read in as touched, and release_before() drops the consumed ones.
// random: as stream, for reads here and there (the head and tail of an input, fingerprinted):
// no readahead beyond the pages touched.
enum class MapMode { whole, stream, random };

class MappedFile {
 public:
  explicit MappedFile(const std::filesystem::path& path, MapMode mode = MapMode::whole);
  MappedFile(std::string name, std::string_view bytes);  // a copy of bytes, called `name`
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  std::string_view view() const { return {data_, size_}; }
  const unsigned char* bytes() const { return reinterpret_cast<const unsigned char*>(data_); }
  std::size_t size() const { return size_; }
  const std::string& name() const { return name_; }  // the path as given, for messages

  // Stream mode: the bytes before `offset` will not be read again; their pages leave this
  // process's resident set (they stay in the page cache). Const because the view is unchanged:
  // a page touched again is read back in. A no-op in whole mode.
  void release_before(std::size_t offset) const;
  // Stream or random mode: the pages overlapping [begin, end) leave the resident set (safe while
  // other threads read them, or the neighbouring bytes of a page on the edge: they are read back
  // in).
  void release(std::size_t begin, std::size_t end) const;

 private:
  std::string name_;
  const char* data_ = nullptr;
  std::size_t size_ = 0;
  void* map_ = nullptr;  // non-null when data_ is an mmap
  MapMode mode_;
  mutable std::size_t released_ = 0;  // page-aligned: bytes already released
  std::vector<char> copy_;
};

}  // namespace g2s::io
