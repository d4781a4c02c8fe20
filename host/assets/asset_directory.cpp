#include <seamcl/assets/asset_directory.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <sstream>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>
#if __has_include(<linux/openat2.h>)
#include <linux/openat2.h>
#endif

#include <seamcl/core/input_error.h>
#include <seamcl/core/over_budget.h>
#include <seamcl/memory/render_memory.h>

namespace seamcl {

// An open file, closed with it. Outside the anonymous namespace: AssetDirectory::OpenedFiles
// holds these.
struct AssetFileDescriptor {
  int fd = -1;
  explicit AssetFileDescriptor(int d) : fd(d) {}
  ~AssetFileDescriptor() {
    if (fd >= 0) ::close(fd);
  }
  AssetFileDescriptor(const AssetFileDescriptor&) = delete;
  AssetFileDescriptor& operator=(const AssetFileDescriptor&) = delete;
};

namespace {

namespace fs = std::filesystem;

// `path` (canonical) is `root` (canonical) or below it.
bool is_within(const fs::path& path, const fs::path& root) {
  auto p = path.begin();
  for (auto r = root.begin(); r != root.end(); ++r, ++p) {
    if (r->empty()) continue;  // a trailing separator
    if (p == path.end() || *p != *r) return false;
  }
  return true;
}

// A file's stamp as text, for the cache key: a changed scene or texture file is a different entry.
std::string stamp_text(const std::optional<FileStamp>& stamp) {
  if (!stamp) return "none";
  std::ostringstream out;
  out << stamp->bytes << "@" << stamp->modified.time_since_epoch().count();
  return out.str();
}

// `relative` ('/'-separated, no '..', not absolute) opened for reading beneath `root_fd`, without
// following a link out of it: -1 and errno on failure (EXDEV or ELOOP: a link out, or any link
// where openat2 is missing).
int open_beneath(int root_fd, const std::string& relative) {
  constexpr int kFlags = O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY;  // a FIFO opens at once, then is refused
#if defined(SYS_openat2) && defined(RESOLVE_BENEATH)
  open_how how{};
  how.flags = kFlags;
  how.resolve = RESOLVE_BENEATH | RESOLVE_NO_MAGICLINKS;
  const long fd = ::syscall(SYS_openat2, root_fd, relative.c_str(), &how, sizeof how);
  if (fd >= 0) return static_cast<int>(fd);
  if (errno != ENOSYS && errno != EPERM) return -1;  // EPERM: a sandbox that filters openat2
#endif
  int dir = ::fcntl(root_fd, F_DUPFD_CLOEXEC, 0);
  if (dir < 0) return -1;
  const fs::path path(relative);
  for (auto part = path.begin(); part != path.end();) {
    const std::string component = part->string();
    const bool last = ++part == path.end();
    if (component.empty() || component == ".") continue;
    const int next = ::openat(dir, component.c_str(), last ? kFlags | O_NOFOLLOW : O_PATH | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    const int saved = errno;
    ::close(dir);
    if (next < 0) {
      errno = saved == ENOTDIR ? ELOOP : saved;  // a symlinked directory component
      return -1;
    }
    dir = next;
  }
  return dir;
}

// `text` with every occurrence of `from` replaced by `to`.
std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  if (from.empty()) return text;
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) text.replace(at, from.size(), to);
  return text;
}

}  // namespace

// One load's opened files: the descriptors, and for each a link in a private directory
// (<links>/<load>/<k>/<file name>, so the loaders see the file's own name and extension) to
// /proc/self/fd/N. Kept as long as the scene made from them, which may read a file later (a
// deferred image face); the links go with it.
struct AssetDirectory::OpenedFiles {
  std::string dir;
  std::vector<std::unique_ptr<AssetFileDescriptor>> descriptors;
  std::map<std::string, std::string> relative_dirs;  // a link's directory -> the file's directory, relative
  std::vector<std::pair<std::string, std::string>> shown;  // a link's path -> the file's relative name
  std::map<std::string, std::string> links;  // a file's relative name -> its link (a file named twice is opened once)
  ~OpenedFiles() {
    std::error_code ignored;
    if (!dir.empty()) fs::remove_all(dir, ignored);
  }
  // `message` naming files by their names in the asset directory rather than any path here.
  std::string relative_message(std::string message, const std::string& root) const {
    std::vector<std::pair<std::string, std::string>> by_length = shown;
    std::sort(by_length.begin(), by_length.end(), [](const auto& a, const auto& b) { return a.first.size() > b.first.size(); });
    for (const auto& [link, name] : by_length) message = replace_all(std::move(message), link, name);
    message = replace_all(std::move(message), dir + "/", "");
    message = replace_all(std::move(message), root + "/", "");
    return replace_all(std::move(message), root, ".");
  }
};

AssetDirectory::AssetDirectory(const std::string& root, AssetCacheLimits limits, FileStamper stamp)
    : limits_(limits), stamp_(std::move(stamp)) {
  std::error_code error;
  if (!fs::is_directory(root, error)) throw InputError("assets", "'" + root + "' is not a directory");
  root_ = fs::canonical(root, error).string();
  if (error) throw InputError("assets", "cannot open '" + root + "': " + error.message());
  root_fd_ = ::open(root_.c_str(), O_PATH | O_DIRECTORY | O_CLOEXEC);
  if (root_fd_ < 0) throw InputError("assets", "cannot open '" + root + "': " + std::strerror(errno));
  std::string links = (fs::temp_directory_path() / "seamcl-assets-XXXXXX").string();
  if (!::mkdtemp(links.data())) {
    ::close(root_fd_);
    throw InputError("assets", std::string("cannot make a private directory in the temporary directory: ") + std::strerror(errno));
  }
  links_dir_ = links;
}

AssetDirectory::~AssetDirectory() {
  // Scenes still held elsewhere keep their own load's links: only this directory's emptied ones go.
  std::error_code ignored;
  for (const auto& entry : fs::directory_iterator(links_dir_, ignored)) {
    if (fs::is_empty(entry.path(), ignored)) fs::remove(entry.path(), ignored);
  }
  fs::remove(links_dir_, ignored);
  if (root_fd_ >= 0) ::close(root_fd_);
}

int AssetDirectory::open_checked(const std::string& name, const std::string& relative_to, const std::string& field,
                                 std::string& relative) const {
  if (name.empty()) throw InputError(field, "must not be empty");
  if (name.find('\0') != std::string::npos) throw InputError(field, "must not hold a NUL character");
  const fs::path given(name);
  if (given.is_absolute() || name.front() == '/' || name.front() == '\\')
    throw InputError(field, "must be a name inside the asset directory, not an absolute path");
  for (const fs::path& part : given)
    if (part == "..") throw InputError(field, "must be a name inside the asset directory ('..' is not allowed)");
  fs::path base;
  if (!relative_to.empty()) {
    const fs::path from = fs::path(relative_to).lexically_relative(root_);
    if (from.empty() || *from.begin() == "..") throw InputError(field, "'" + name + "' leads out of the asset directory");
    if (from != ".") base = from;
  }
  relative = (base / given).lexically_normal().generic_string();
  const int fd = open_beneath(root_fd_, relative);
  if (fd < 0) {
    if (errno == EXDEV || errno == ELOOP) throw InputError(field, "'" + name + "' leads out of the asset directory");
    if (errno == ENOENT) throw InputError(field, "no asset '" + name + "' in the asset directory");
    throw InputError(field, "cannot open '" + name + "': " + std::strerror(errno));
  }
  struct stat info {};
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
    ::close(fd);
    throw InputError(field, "'" + name + "' is not a file");
  }
  return fd;
}

std::vector<AssetEntry> AssetDirectory::list() const {
  std::vector<AssetEntry> out;
  std::error_code error;
  fs::recursive_directory_iterator it(root_, fs::directory_options::skip_permission_denied, error), end;
  for (; !error && it != end && out.size() < kMaxListed; it.increment(error)) {
    const fs::path& path = it->path();
    if (path.filename().string().starts_with(".")) {
      if (it->is_directory(error)) it.disable_recursion_pending();
      continue;
    }
    if (it->is_symlink(error) && it->is_directory(error)) {
      it.disable_recursion_pending();
      continue;
    }
    const std::optional<AssetKind> kind = asset_kind_of_path(path.string());
    if (!kind || !it->is_regular_file(error)) continue;
    const fs::path target = fs::canonical(path, error);
    if (error || !is_within(target, root_)) {
      error.clear();
      continue;
    }
    // Listed under its own name (a link inside the directory is a name a request may give).
    out.push_back({path.lexically_relative(root_).generic_string(), *kind, fs::file_size(target, error)});
  }
  std::sort(out.begin(), out.end(), [](const AssetEntry& a, const AssetEntry& b) { return a.name < b.name; });
  return out;
}

std::string AssetDirectory::resolve(const std::string& name, const std::string& relative_to, const std::string& field) const {
  std::string relative;
  AssetFileDescriptor opened(open_checked(name, relative_to, field, relative));
  return (fs::path(root_) / relative).string();
}

std::shared_ptr<const Scene> AssetDirectory::load(const std::string& scene, const std::string& texture,
                                                  SceneSourceOptions options) {
  // Every file the load resolves, stamped when resolved (before it is read), so that a file
  // changed while or after it is read makes the entry stale rather than the stamp new.
  auto files = std::make_shared<FileStamps>();
  auto opened = std::make_shared<OpenedFiles>();
  opened->dir = links_dir_ + "/" + std::to_string(link_sequence_.fetch_add(1));
  options.resolve = [this, files, opened](const std::string& name, const std::string& relative_to, const std::string& field) {
    // A name inside a scene file is relative to that file's directory, which the loader knows by
    // the file's link.
    std::string base = relative_to;
    if (const auto found = opened->relative_dirs.find(relative_to); found != opened->relative_dirs.end())
      base = (fs::path(root_) / found->second).string();
    std::string relative;
    auto descriptor = std::make_unique<AssetFileDescriptor>(open_checked(name, base, field, relative));
    if (const auto known = opened->links.find(relative); known != opened->links.end()) return known->second;
    const std::string path = (fs::path(root_) / relative).string();
    if (!files->contains(path)) files->emplace(path, stamp_(path));
    const std::string link_dir = opened->dir + "/" + std::to_string(opened->descriptors.size());
    fs::create_directories(link_dir);
    const std::string link = link_dir + "/" + fs::path(relative).filename().string();
    fs::create_symlink("/proc/self/fd/" + std::to_string(descriptor->fd), link);
    opened->relative_dirs[link_dir] = fs::path(relative).parent_path().generic_string();
    opened->shown.emplace_back(link, relative);
    opened->links[relative] = link;
    opened->descriptors.push_back(std::move(descriptor));
    return link;
  };
  std::ostringstream key;
  const std::string scene_path = resolve(scene, "", "scene");
  key << scene_path << "|" << stamp_text(stamp_(scene_path)) << "|";
  if (!texture.empty()) {
    const std::string texture_path = resolve(texture, "", "texture");
    key << texture_path << "|" << stamp_text(stamp_(texture_path));
  }
  key << "|";
  if (!options.displacement_map.empty()) {
    const std::string map_path = resolve(options.displacement_map, "", "displacement_map");
    key << map_path << "|" << stamp_text(stamp_(map_path));
  }
  // Deferred or baked is part of the key: a caller that reads the stored texels must not be handed
  // a deferred scene, nor one that packs face by face a baked one (its float copy of every face).
  key << "|" << options.generator.tint << "|" << options.generator.defer_textures << "|" << options.mesh_texture_size
      << "|" << options.ptex_limits.max_texels;
  if (options.generator.constant_color) {
    const glm::vec3 c = *options.generator.constant_color;
    key << "|" << c.r << "," << c.g << "," << c.b;
  }
  // The entry, if any, under the lock; its files stamped outside it, so that a cache hit does not
  // hold up other requests while it stats its files. The lock never kept the files from changing:
  // a hit serves the scene whose files had their stamps when they were taken, as it did under the
  // lock. Meanwhile the entry may have been evicted, or found stale and replaced, by another load:
  // a fresh one is served all the same (it is what the stamps say), a stale one is loaded again.
  std::shared_ptr<const Scene> cached;
  std::shared_ptr<const FileStamps> stamps;
  {
    std::lock_guard lock(mutex_);
    const auto found = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.key == key.str(); });
    if (found != entries_.end()) {
      cached = found->scene;
      stamps = found->files;
    }
  }
  const bool fresh = cached && std::all_of(stamps->begin(), stamps->end(), [this](const auto& file) {
                       return stamp_(file.first) == file.second;
                     });
  {
    std::lock_guard lock(mutex_);
    const auto found = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.scene == cached; });
    if (fresh) {
      if (found != entries_.end()) entries_.splice(entries_.begin(), entries_, found);
      return cached;
    }
    if (cached && found != entries_.end()) {  // a file it read has changed since: loaded again below
      bytes_ -= found->bytes;
      entries_.erase(found);
    }
    ++loads_;
  }
  // Read outside the lock: a large file does not hold up requests for cached ones.
  // The scene keeps its load's descriptors and links: a deferred face reads its file when packed.
  std::shared_ptr<const Scene> loaded;
  try {
    loaded = std::shared_ptr<const Scene>(new Scene(load_scene_source(scene, texture, options)),
                                          [opened](const Scene* made) { delete made; });
  } catch (const OverBudget&) {
    throw;
  } catch (const InputError& e) {
    const std::string what = e.what();
    const std::string message = what.size() >= e.field().size() + 2 ? what.substr(e.field().size() + 2) : what;
    throw InputError(e.field(), opened->relative_message(message, root_));
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(opened->relative_message(e.what(), root_));
  }
  // With what its texture_source keeps to make the faces from (a deferred .ptx's whole file,
  // metadata included, also one named inside a scene file).
  const size_t bytes = scene_held_bytes(*loaded);
  std::lock_guard lock(mutex_);
  if (bytes > limits_.max_bytes || limits_.max_entries == 0) return loaded;
  entries_.push_front({key.str(), loaded, bytes, std::move(files)});
  bytes_ += bytes;
  while (entries_.size() > limits_.max_entries || bytes_ > limits_.max_bytes) {
    bytes_ -= entries_.back().bytes;
    entries_.pop_back();
  }
  return loaded;
}

size_t AssetDirectory::cached_entries() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

size_t AssetDirectory::cached_bytes() const {
  std::lock_guard lock(mutex_);
  return bytes_;
}

long long AssetDirectory::file_loads() const {
  std::lock_guard lock(mutex_);
  return loads_;
}

}  // namespace seamcl
