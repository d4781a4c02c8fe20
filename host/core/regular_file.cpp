#include <seamcl/core/regular_file.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace seamcl {

RegularFile::RegularFile(const std::string& path) {
  // The path first, so that a device named by mistake is not opened at all (opening some has
  // effects: a tape rewinds, a watchdog arms); the descriptor's fstat below stays the authority.
  struct stat status {};
  if (::stat(path.c_str(), &status) == 0 && !S_ISREG(status.st_mode)) {
    refusal_ = Refusal::NotRegular;
    return;
  }
  // O_NOCTTY: a terminal device swapped in must not become the process's terminal.
  descriptor_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (descriptor_ < 0) {
    error_number_ = errno;
    refusal_ = error_number_ == ENOENT ? Refusal::Missing : Refusal::Unreadable;
    return;
  }
  if (::fstat(descriptor_, &status) != 0) {
    error_number_ = errno;
    refusal_ = Refusal::Unreadable;
  } else if (!S_ISREG(status.st_mode)) {
    refusal_ = Refusal::NotRegular;
  } else {
    size_ = static_cast<std::uintmax_t>(status.st_size);
    // Blocking again for the reads: FUSE and network file systems pass O_NONBLOCK on, and a read
    // there could fail with EAGAIN where it should wait.
    const int flags = ::fcntl(descriptor_, F_GETFL);
    if (flags == -1 || ::fcntl(descriptor_, F_SETFL, flags & ~O_NONBLOCK) == -1) {
      error_number_ = errno;
      refusal_ = Refusal::Unreadable;
    }
  }
}

std::string RegularFile::refusal_text() const {
  switch (refusal_) {
    case Refusal::None: return "";
    case Refusal::Missing: return "no such file";
    case Refusal::NotRegular: return "not a regular file";
    case Refusal::Unreadable: break;
  }
  return std::strerror(error_number_);
}

RegularFile::~RegularFile() {
  if (descriptor_ >= 0) ::close(descriptor_);
}

template <class Bytes>
bool RegularFile::read_into(Bytes& out, std::uintmax_t max_bytes) {
  out.clear();
  if (refusal_ != Refusal::None) return false;
  const std::uintmax_t limit = max_bytes == UINTMAX_MAX ? max_bytes : max_bytes + 1;
  const auto fail = [&] {
    error_number_ = errno;
    refusal_ = Refusal::Unreadable;
    out.clear();
    return false;
  };
  // The stated size in one allocation (the buffer may be most of a process's memory: no doubling).
  out.resize(static_cast<size_t>(std::min(size_, limit)));
  size_t held = 0;
  while (held < out.size()) {
    const ssize_t got = ::pread(descriptor_, out.data() + held, out.size() - held, static_cast<off_t>(held));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return fail();
    if (got == 0) {  // shorter than fstat said: it shrank since
      out.resize(held);
      return true;
    }
    held += static_cast<size_t>(got);
  }
  // Then on, in chunks, only if it grew since the fstat: still no further than the bound.
  char chunk[1 << 16];
  while (held < limit) {
    const ssize_t got = ::pread(descriptor_, chunk, static_cast<size_t>(std::min<std::uintmax_t>(sizeof chunk, limit - held)),
                                static_cast<off_t>(held));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return fail();
    if (got == 0) break;
    out.insert(out.end(), chunk, chunk + got);
    held += static_cast<size_t>(got);
  }
  return true;
}

bool RegularFile::read_all(std::string& out, std::uintmax_t max_bytes) { return read_into(out, max_bytes); }

bool RegularFile::read_all(std::vector<uint8_t>& out, std::uintmax_t max_bytes) { return read_into(out, max_bytes); }

}  // namespace seamcl
