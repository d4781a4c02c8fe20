// How the asset code tells that a file it read has changed since: its size and modification time.
// (A rewrite of the same size within one tick of the file system's clock is not seen; readers that
// depend on a file's shape check it again when they read it.)
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace seamcl {

struct FileStamp {
  std::uintmax_t bytes = 0;
  std::filesystem::file_time_type modified{};
  bool operator==(const FileStamp&) const = default;
};

// The stamp of the regular file at `path` (symlinks followed); nullopt when there is none to look
// at (gone, not a regular file, not readable).
std::optional<FileStamp> file_stamp(const std::string& path);

}  // namespace seamcl
