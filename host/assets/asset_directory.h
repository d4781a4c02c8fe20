// A directory of assets that a service renders from (`seamcl serve --assets DIR`): names relative
// to it, and nothing else on disk. Every name a client gives, and every name a scene file in it
// gives, resolves here: an absolute path, a `..` component or a symlink that leads out of the
// directory is refused, naming the field. Loaded scenes are cached, bounded in bytes and entries,
// so repeated requests do not read the files again.
//
// A name is opened relative to the directory's descriptor, never by its path: openat2 with
// RESOLVE_BENEATH where the kernel has it (symlinks inside the directory followed, none out of
// it), else one openat with O_NOFOLLOW per component (no symlink followed at all). The checks
// (a regular file) are made on the opened descriptor, and the loaders read that descriptor (by a
// private link to /proc/self/fd/N, since they take paths): a name swapped for a symlink after
// the check cannot make them read another file. Errors name files relative to the directory,
// never by the server's paths.
#pragma once
#include <cstddef>
#include <atomic>
#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <seamcl/assets/file_stamp.h>
#include <seamcl/assets/scene_source.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

struct AssetEntry {
  std::string name;  // relative to the directory, '/'-separated
  AssetKind kind;
  std::uintmax_t bytes = 0;
};

struct AssetCacheLimits {
  size_t max_bytes = size_t{512} << 20;  // host bytes of the cached scenes (scene_host_bytes); 0: cache nothing
  size_t max_entries = 8;
};

class AssetDirectory {
 public:
  // How the cache stamps a file (file_stamp; a test may watch the calls).
  using FileStamper = std::function<std::optional<FileStamp>(const std::string& path)>;

  // `root` must be an existing directory: InputError("assets") otherwise.
  explicit AssetDirectory(const std::string& root, AssetCacheLimits limits = {}, FileStamper stamp = file_stamp);
  ~AssetDirectory();
  AssetDirectory(const AssetDirectory&) = delete;
  AssetDirectory& operator=(const AssetDirectory&) = delete;

  const std::string& root() const { return root_; }

  // Every .json, .obj and .ptx file under the directory, sorted by name: at most kMaxListed, no
  // hidden files or directories, symlinked directories not entered, symlinked files (under their
  // own name) only when they resolve inside the directory.
  static constexpr size_t kMaxListed = 1000;
  std::vector<AssetEntry> list() const;

  // The path of `name` inside the directory (`relative_to`: a directory inside it, empty for the
  // directory itself). InputError(field) for an empty or absolute name, a `..` component, a name
  // that resolves outside the directory (symlinks followed) and a name that is not a file here.
  std::string resolve(const std::string& name, const std::string& relative_to, const std::string& field) const;

  // load_scene_source with every name resolved here; from the cache when the same names with the
  // same options were loaded before and every file the load resolved (the scene, the texture,
  // options.displacement_map, and the files a scene file names: meshes, .ptx, face and
  // environment images) still has the size and modification time it had when it was resolved; otherwise loaded again. (A deferred image
  // face reads its file when packed: a cached scene must not name a file changed since.) The
  // files are stamped outside the cache's lock.
  std::shared_ptr<const Scene> load(const std::string& scene, const std::string& texture, SceneSourceOptions options);

  size_t cached_entries() const;
  size_t cached_bytes() const;
  long long file_loads() const;  // cache misses so far

 private:
  using FileStamps = std::map<std::string, std::optional<FileStamp>>;
  struct Entry {
    std::string key;
    std::shared_ptr<const Scene> scene;
    size_t bytes = 0;
    // Every path the load resolved, once (a file many faces name is checked once), and its stamp
    // when first resolved.
    std::shared_ptr<const FileStamps> files;
  };

  struct OpenedFiles;  // one load's descriptors and the private links the loaders read them by
  // `name` (relative to `relative_to`) opened beneath the directory and checked on its descriptor.
  int open_checked(const std::string& name, const std::string& relative_to, const std::string& field, std::string& relative) const;

  std::string root_;  // canonical
  int root_fd_ = -1;  // the directory, opened once (O_PATH)
  std::string links_dir_;  // private (0700): per load, a link to each opened descriptor
  mutable std::atomic<long long> link_sequence_{0};
  AssetCacheLimits limits_;
  FileStamper stamp_;
  mutable std::mutex mutex_;
  std::list<Entry> entries_;  // most recently used first
  size_t bytes_ = 0;
  long long loads_ = 0;
};

}  // namespace seamcl
