#include <seamcl/assets/asset_directory.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <sstream>

#include <seamcl/core/input_error.h>
#include <seamcl/memory/render_memory.h>

namespace seamcl {
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

}  // namespace

AssetDirectory::AssetDirectory(const std::string& root, AssetCacheLimits limits, FileStamper stamp)
    : limits_(limits), stamp_(std::move(stamp)) {
  std::error_code error;
  if (!fs::is_directory(root, error)) throw InputError("assets", "'" + root + "' is not a directory");
  root_ = fs::canonical(root, error).string();
  if (error) throw InputError("assets", "cannot open '" + root + "': " + error.message());
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
    out.push_back({fs::relative(path, root_).generic_string(), *kind, fs::file_size(target, error)});
  }
  std::sort(out.begin(), out.end(), [](const AssetEntry& a, const AssetEntry& b) { return a.name < b.name; });
  return out;
}

std::string AssetDirectory::resolve(const std::string& name, const std::string& relative_to, const std::string& field) const {
  if (name.empty()) throw InputError(field, "must not be empty");
  const fs::path given(name);
  if (given.is_absolute() || name.front() == '/' || name.front() == '\\')
    throw InputError(field, "must be a name inside the asset directory, not an absolute path");
  for (const fs::path& part : given)
    if (part == "..") throw InputError(field, "must be a name inside the asset directory ('..' is not allowed)");
  if (name.find('\0') != std::string::npos) throw InputError(field, "must not hold a NUL character");
  const fs::path base = relative_to.empty() ? fs::path(root_) : fs::path(relative_to);
  std::error_code error;
  const fs::path resolved = fs::canonical(base / given, error);
  if (error) throw InputError(field, "no asset '" + name + "' in the asset directory");
  if (!is_within(resolved, root_)) throw InputError(field, "'" + name + "' leads out of the asset directory");
  if (!fs::is_regular_file(resolved, error)) throw InputError(field, "'" + name + "' is not a file");
  return resolved.string();
}

std::shared_ptr<const Scene> AssetDirectory::load(const std::string& scene, const std::string& texture,
                                                  SceneSourceOptions options) {
  // Every file the load resolves, stamped when resolved (before it is read), so that a file
  // changed while or after it is read makes the entry stale rather than the stamp new.
  auto files = std::make_shared<FileStamps>();
  options.resolve = [this, files](const std::string& name, const std::string& relative_to, const std::string& field) {
    std::string path = resolve(name, relative_to, field);
    if (!files->contains(path)) files->emplace(path, stamp_(path));
    return path;
  };
  std::ostringstream key;
  const std::string scene_path = resolve(scene, "", "scene");
  key << scene_path << "|" << stamp_text(stamp_(scene_path)) << "|";
  if (!texture.empty()) {
    const std::string texture_path = resolve(texture, "", "texture");
    key << texture_path << "|" << stamp_text(stamp_(texture_path));
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
  auto loaded = std::make_shared<const Scene>(load_scene_source(scene, texture, options));
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
