// MappedFile: maps an input file read-only (MAP_POPULATE, sequential advice) so the readers can
// parse it in place; falls back to read() for files whose size stat does not know (/proc).
// Devices, FIFOs and sockets are refused: they may never end. Every OS
// failure becomes Error(bad_input, "<file>: <what>: <strerror>").
#include "io/mapped_file.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "g2s/error.hpp"

namespace g2s::io {
namespace {

[[noreturn]] void fail_errno(const std::string& name, const char* what, int err) {
  throw Error(Exit::bad_input, fmt::format("{}: {}: {}", name, what, std::strerror(err)));
}

}  // namespace

InputFile::InputFile(const std::filesystem::path& path) : name_(path.string()) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) fail_errno(name_, "cannot open", errno);
  struct stat st {};
  const int stat_error = ::fstat(fd_, &st) != 0 ? errno : 0;
  if (stat_error != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd_);  // no destructor runs after a constructor throws
    if (stat_error != 0) fail_errno(name_, "cannot stat", stat_error);
    if (S_ISDIR(st.st_mode)) {
      throw Error(Exit::bad_input, fmt::format("{}: is a directory, expected a file", name_));
    }
    // A device or FIFO may never end (/dev/zero, a pipe from `yes`): reading it whole would
    // fill the memory, so only regular files are read.
    throw Error(
        Exit::bad_input,
        fmt::format("{}: not a regular file (a device, FIFO or socket); give a file", name_));
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
}

InputFile::~InputFile() {
  ::close(fd_);
}

void InputFile::read_at(std::uint64_t offset, void* data, std::size_t bytes) const {
  auto* out = static_cast<char*>(data);
  for (std::size_t done = 0; done < bytes;) {
    const ssize_t n = ::pread(fd_, out + done, bytes - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail_errno(name_, "cannot read", errno);
    if (n == 0) {
      throw Error(Exit::bad_input,
                  fmt::format("{}: truncated while it was read ({} bytes wanted at {})", name_,
                              bytes, offset));
    }
    done += static_cast<std::size_t>(n);
  }
}

MappedFile::MappedFile(const std::filesystem::path& path, MapMode mode)
    : name_(path.string()), mode_(mode) {
  const InputFile file(path);
  const int fd = file.fd();
  if (file.size() > 0) {
    size_ = static_cast<std::size_t>(file.size());
    const int populate = mode == MapMode::whole ? MAP_POPULATE : 0;
    void* map = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE | populate, fd, 0);
    if (map == MAP_FAILED) fail_errno(name_, "cannot map", errno);
    ::madvise(map, size_, mode == MapMode::random ? MADV_RANDOM : MADV_SEQUENTIAL);
    map_ = map;
    data_ = static_cast<const char*>(map);
    return;
  }
  // Regular files whose stat size is 0 (/proc): read to the end.
  std::size_t used = 0;
  copy_.resize(1 << 16);
  for (;;) {
    if (used == copy_.size()) copy_.resize(copy_.size() * 2);
    const ssize_t got = ::read(fd, copy_.data() + used, copy_.size() - used);
    if (got < 0) {
      if (errno == EINTR) continue;
      fail_errno(name_, "cannot read", errno);
    }
    if (got == 0) break;
    used += static_cast<std::size_t>(got);
  }
  copy_.resize(used);
  data_ = copy_.data();
  size_ = used;
}

void MappedFile::release_before(std::size_t offset) const {
  if (mode_ != MapMode::stream || map_ == nullptr) return;
  const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  const std::size_t end = std::min(offset, size_) / page * page;
  if (end <= released_) return;
  ::madvise(static_cast<char*>(map_) + released_, end - released_, MADV_DONTNEED);
  released_ = end;
}

void MappedFile::release(std::size_t begin, std::size_t end) const {
  if (mode_ == MapMode::whole || map_ == nullptr) return;
  const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  const std::size_t first = begin / page * page;
  const std::size_t last =
      std::min((end + page - 1) / page * page, (size_ + page - 1) / page * page);
  if (first < last) ::madvise(static_cast<char*>(map_) + first, last - first, MADV_DONTNEED);
}

MappedFile::MappedFile(std::string name, std::string_view bytes)
    : name_(std::move(name)), copy_(bytes.begin(), bytes.end()) {
  data_ = copy_.data();
  size_ = copy_.size();
}

MappedFile::~MappedFile() {
  if (map_ != nullptr) ::munmap(map_, size_);
}

}  // namespace g2s::io
