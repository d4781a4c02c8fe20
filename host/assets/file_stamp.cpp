#include <seamcl/assets/file_stamp.h>

#include <system_error>

namespace seamcl {

std::optional<FileStamp> file_stamp(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return std::nullopt;
  FileStamp stamp;
  stamp.bytes = std::filesystem::file_size(path, error);
  if (error) return std::nullopt;
  stamp.modified = std::filesystem::last_write_time(path, error);
  if (error) return std::nullopt;
  return stamp;
}

}  // namespace seamcl
