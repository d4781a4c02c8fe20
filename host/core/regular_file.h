// Reading a file a user named, so that the check that it is a regular file and the read are on
// one file. Checking the path first (stat) and opening it after leaves a gap: a path swapped for
// a FIFO in between would block the open until something wrote to it. Here the path is opened
// without blocking (a FIFO opens at once) and the open descriptor is checked, then set blocking
// again and read. (The path is also checked before the open, only so that a device named by
// mistake is never opened; the descriptor's check decides.)
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace seamcl {

class RegularFile {
 public:
  enum class Refusal {
    None,        // open, a regular file
    Missing,     // no such file (or a dangling link)
    NotRegular,  // a directory, FIFO, device or socket
    Unreadable,  // open, fstat or a read failed otherwise: error_number() says why
  };

  explicit RegularFile(const std::string& path);
  ~RegularFile();
  RegularFile(const RegularFile&) = delete;
  RegularFile& operator=(const RegularFile&) = delete;

  Refusal refusal() const { return refusal_; }
  int error_number() const { return error_number_; }  // errno of the failure, for strerror
  std::uintmax_t size() const { return size_; }        // as fstat saw it at the open
  // For a message after the path: "no such file", "not a regular file", or strerror's text.
  std::string refusal_text() const;

  // The file from its start into `out`, stopping once it holds more than `max_bytes` (so a file
  // that grew past its stated size is still bounded): false when a read fails (then Unreadable).
  // out.size() > max_bytes means too large.
  bool read_all(std::string& out, std::uintmax_t max_bytes);
  bool read_all(std::vector<uint8_t>& out, std::uintmax_t max_bytes);

 private:
  template <class Bytes>
  bool read_into(Bytes& out, std::uintmax_t max_bytes);

  int descriptor_ = -1;
  Refusal refusal_ = Refusal::None;
  int error_number_ = 0;
  std::uintmax_t size_ = 0;
};

}  // namespace seamcl
