// AtomicFile: output appears at its target only when complete. Writes go through a 1 MiB buffer
// to ".NAME.tmp-<pid>-<n>" beside the target; commit() flushes, closes (checking the result, so
// delayed write errors surface) and renames. No fsync: speed over surviving a power cut.
// A target that is a symbolic link is written through: the file it names is replaced, the link
// stays. An existing target that is not a regular file (a device such as /dev/null, a FIFO, a
// socket) is refused: renaming over it would replace the node itself.
#include <fcntl.h>
#include <fmt/core.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "io/temp_registry.hpp"
#include "io/write_behind.hpp"

namespace g2s {
namespace {

constexpr std::size_t kBufferSize = 1u << 20;
std::atomic<std::uint64_t> g_counter{0};

[[noreturn]] void fail_write(const std::filesystem::path& target, const char* what, int err) {
  throw Error(Exit::write_failed,
              fmt::format("{}: {}: {}", target.string(), what, std::strerror(err)));
}

// The file a chain of symbolic links ends at (`path` itself when it is no link); a dangling
// link gives the path it points to, which is then created.
std::filesystem::path follow_links(const std::filesystem::path& path) {
  std::filesystem::path at = path;
  for (int hop = 0; hop < 40; ++hop) {
    struct stat st {};
    if (::lstat(at.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return at;
    std::error_code ec;
    const std::filesystem::path next = std::filesystem::read_symlink(at, ec);
    if (ec) fail_write(path, "cannot read the symbolic link", ec.value());
    at = next.is_absolute() ? next : at.parent_path() / next;
  }
  fail_write(path, "cannot write", ELOOP);
}

}  // namespace

std::filesystem::path hidden_beside(const std::filesystem::path& target, std::string_view tag) {
  constexpr std::size_t kNameMax = 255;  // bytes in a name on Linux's file systems
  std::string name = target.filename().string();
  const std::size_t room = kNameMax - std::min(kNameMax, tag.size() + 2);  // "." name "." tag
  if (name.size() > room) name.resize(room);
  return target.parent_path() / fmt::format(".{}.{}", name, tag);
}

AtomicFile::AtomicFile(const std::filesystem::path& target) : target_(target) {
  const std::string name = target_.filename().string();
  if (name.empty() || name == "." || name == "..") {
    throw Error(Exit::write_failed,
                fmt::format("{}: not a file name (the path names a folder)", target_.string()));
  }
  destination_ = follow_links(target_);
  struct stat st {};
  if (::stat(destination_.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) fail_write(target_, "cannot write", EISDIR);
    if (!S_ISREG(st.st_mode)) {
      throw Error(Exit::write_failed,
                  fmt::format("{}: not a regular file (a device, FIFO or socket); g2s writes "
                              "its output only to regular files",
                              target_.string()));
    }
  }
  temporary_ = hidden_beside(destination_,
                             fmt::format("tmp-{}-{}", static_cast<long>(::getpid()), g_counter++));
  // Registered before it exists, so a signal arriving just after it appears still removes it.
  registry_slot_ = register_temporary(temporary_.c_str());
  fd_ = ::open(temporary_.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd_ < 0) {
    const int err = errno;
    unregister_temporary(registry_slot_);
    registry_slot_ = -1;
    temporary_.clear();
    fail_write(target_, "cannot create", err);
  }
  buffer_.reserve(kBufferSize);
}

AtomicFile::~AtomicFile() {
  behind_.reset();  // its thread may be writing to fd_
  if (fd_ >= 0) ::close(fd_);
  if (!committed_ && !temporary_.empty()) ::unlink(temporary_.c_str());
  unregister_temporary(registry_slot_);
}

void AtomicFile::write_out(const char* p, std::size_t bytes) {
  while (bytes > 0) {
    const ssize_t n = ::pwrite(fd_, p, bytes, static_cast<off_t>(written_));
    if (n < 0) {
      if (errno == EINTR) continue;
      fail_write(target_, "write failed", errno);
    }
    if (n == 0) fail_write(target_, "write failed", EIO);
    p += n;
    bytes -= static_cast<std::size_t>(n);
    written_ += static_cast<std::uint64_t>(n);
  }
}

void AtomicFile::wait_behind() const {
  if (!behind_) return;
  if (const int err = behind_->wait(); err != 0) fail_write(target_, "write failed", err);
}

void AtomicFile::flush_buffer() {
  if (!behind_) {
    write_out(buffer_.data(), buffer_.size());
    buffer_.clear();
    return;
  }
  const std::size_t bytes = buffer_.size();
  if (bytes == 0) return;
  if (const int err = behind_->submit(buffer_, written_); err != 0) {
    fail_write(target_, "write failed", err);
  }
  written_ += bytes;
}

void AtomicFile::write(const void* data, std::size_t bytes) {
  if (fd_ < 0) fail_write(target_, "write after commit", EBADF);
  const char* p = static_cast<const char*>(data);
  if (buffer_.size() + bytes > kBufferSize) {
    flush_buffer();
    // A block as large as the buffer goes straight to the OS.
    if (bytes >= kBufferSize) {
      wait_behind();
      write_out(p, bytes);
      return;
    }
  }
  buffer_.insert(buffer_.end(), p, p + bytes);
}

void AtomicFile::write_behind() {
  if (!behind_) behind_ = std::make_unique<WriteBehind>(fd_, kBufferSize);
}

double AtomicFile::write_behind_cpu_seconds() const {
  return behind_ ? behind_->cpu_seconds() : behind_cpu_;
}

void AtomicFile::write_at(std::uint64_t offset, const void* data, std::size_t bytes) {
  if (fd_ < 0) fail_write(target_, "write after commit", EBADF);
  if (offset > size() || bytes > size() - offset) {
    throw Error(Exit::failure, fmt::format("{}: write_at({}, {} bytes) beyond the {} bytes written",
                                           target_.string(), offset, bytes, size()));
  }
  const char* p = static_cast<const char*>(data);
  wait_behind();
  // The part already handed to the OS.
  while (bytes > 0 && offset < written_) {
    const std::size_t part =
        static_cast<std::size_t>(std::min<std::uint64_t>(bytes, written_ - offset));
    const ssize_t n = ::pwrite(fd_, p, part, static_cast<off_t>(offset));
    if (n < 0) {
      if (errno == EINTR) continue;
      fail_write(target_, "write failed", errno);
    }
    if (n == 0) fail_write(target_, "write failed", EIO);
    p += n;
    bytes -= static_cast<std::size_t>(n);
    offset += static_cast<std::uint64_t>(n);
  }
  // The part still in the buffer.
  if (bytes > 0) std::memcpy(buffer_.data() + (offset - written_), p, bytes);
}

void AtomicFile::flush() {
  if (fd_ < 0) fail_write(target_, "write after commit", EBADF);
  flush_buffer();
  wait_behind();
}

void AtomicFile::read_at(std::uint64_t offset, void* data, std::size_t bytes) const {
  if (fd_ < 0 || offset > written_ || bytes > written_ - offset) {
    throw Error(Exit::failure, fmt::format("{}: read_at({}, {} bytes) beyond the {} bytes flushed",
                                           target_.string(), offset, bytes, written_));
  }
  wait_behind();
  char* p = static_cast<char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::pread(fd_, p, bytes, static_cast<off_t>(offset));
    if (n < 0) {
      if (errno == EINTR) continue;
      fail_write(target_, "cannot read back", errno);
    }
    if (n == 0) fail_write(target_, "cannot read back", EIO);
    p += n;
    bytes -= static_cast<std::size_t>(n);
    offset += static_cast<std::uint64_t>(n);
  }
}

std::uint64_t AtomicFile::size() const {
  return written_ + buffer_.size();
}

void AtomicFile::commit() {
  if (fd_ < 0) fail_write(target_, "commit after commit", EBADF);
  flush_buffer();
  wait_behind();
  behind_cpu_ = write_behind_cpu_seconds();
  behind_.reset();
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) fail_write(target_, "write failed", errno);
  if (::rename(temporary_.c_str(), destination_.c_str()) != 0)
    fail_write(target_, "cannot rename into place", errno);
  committed_ = true;
  unregister_temporary(registry_slot_);
  registry_slot_ = -1;
}

}  // namespace g2s

namespace g2s {

TemporaryPath::TemporaryPath(std::filesystem::path path) : path_(std::move(path)) {
  registry_slot_ = register_temporary(path_.c_str());
}

TemporaryPath::~TemporaryPath() {
  std::error_code ignored;
  std::filesystem::remove(path_, ignored);
  unregister_temporary(registry_slot_);
}

}  // namespace g2s
