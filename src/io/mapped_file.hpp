// Read-only view of a whole input file for the readers: mmap for regular files (no copy, the
// page cache does the work), a read() loop for pipes and /proc-like files, or a copy of bytes
// already in memory (the fuzz targets: an exactly sized heap buffer, so a read past the end is
// caught by AddressSanitizer, which an mmap's page padding would hide). Opening problems
// (missing, directory, permission) throw Error(bad_input) naming the file.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace g2s::io {

class MappedFile {
 public:
  explicit MappedFile(const std::filesystem::path& path);
  MappedFile(std::string name, std::string_view bytes);  // a copy of bytes, called `name`
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  std::string_view view() const { return {data_, size_}; }
  const unsigned char* bytes() const { return reinterpret_cast<const unsigned char*>(data_); }
  std::size_t size() const { return size_; }
  const std::string& name() const { return name_; }  // the path as given, for messages

 private:
  std::string name_;
  const char* data_ = nullptr;
  std::size_t size_ = 0;
  void* map_ = nullptr;  // non-null when data_ is an mmap
  std::vector<char> copy_;
};

}  // namespace g2s::io
