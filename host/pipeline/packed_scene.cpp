#include <seamcl/pipeline/packed_scene.h>


#include "core/srgb.h"
#include "pipeline/adjacency.h"
#include "pipeline/guard_band.h"
#include "pipeline/reflective_face.h"
#include "scene/budgeted_faces.h"

#include <algorithm>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

namespace seamcl {
namespace {

void store_texel(PackedScene& out, size_t at, const glm::vec4& texel) {
  if (out.format == TexelFormat::Rgba8) {
    out.texels8[at] = encode_srgb8(texel);
  } else {
    float* stored = &out.texels32[4 * at];
    stored[0] = texel.r;
    stored[1] = texel.g;
    stored[2] = texel.b;
    stored[3] = texel.a;
  }
}

// store_texel for `count` texels in a row from `at`: the packed scene's bulk, encoded in one call.
void store_texels(PackedScene& out, size_t at, const glm::vec4* texels, size_t count) {
  if (out.format == TexelFormat::Rgba8) {
    encode_srgb8(texels, count, out.texels8.data() + at);
  } else {
    for (size_t i = 0; i < count; ++i) store_texel(out, at + i, texels[i]);
  }
}

// Writes face f's levels (banded when guard_band > 0) at their offsets in `out`'s texels.
void pack_face_texels(const Scene& scene, PackedScene& out, size_t f, size_t first_level) {
  // A deferred face's chain is made here and dropped on return: one face's floats at a time.
  const MipChain made = is_deferred(scene.faces[f].texture) ? face_texture(scene, f) : MipChain{};
  const MipChain& chain = made.levels.empty() ? scene.faces[f].texture : made;
  for (size_t l = 0; l < chain.levels.size(); ++l) {
    const TextureLevel banded = out.guard_band > 0 ? guard_banded_level(scene, out.neighbors, static_cast<uint32_t>(f),
                                                                        static_cast<int>(l), out.guard_band)
                                                   : TextureLevel{};
    const TextureLevel& level = out.guard_band > 0 ? banded : chain.levels[l];
    const size_t band = static_cast<size_t>(out.guard_band);
    if (level.texels.size() != (static_cast<size_t>(chain.levels[l].width) + 2 * band) *
                                   (static_cast<size_t>(chain.levels[l].height) + 2 * band)) {
      throw std::logic_error("pack_scene: face " + std::to_string(f) + " level " + std::to_string(l) +
                             " holds other than its size's texels");
    }
    store_texels(out, out.level_offsets[first_level + l], level.texels.data(), level.texels.size());
  }
}

// Face f's own texels into the middle of its banded levels (the bands are written apart).
void pack_own_texels(const MipChain& chain, PackedScene& out, size_t f, size_t first_level) {
  const int band = out.guard_band;
  for (size_t l = 0; l < chain.levels.size(); ++l) {
    const TextureLevel& level = chain.levels[l];
    if (level.texels.size() != static_cast<size_t>(level.width) * static_cast<size_t>(level.height))
      throw std::logic_error("pack_scene: face " + std::to_string(f) + " level " + std::to_string(l) +
                             " holds other than its size's texels");
    const size_t stored_width = static_cast<size_t>(level.width + 2 * band);
    const size_t first = out.level_offsets[first_level + l];
    for (int j = 0; j < level.height; ++j)
      for (int i = 0; i < level.width; ++i)
        store_texel(out, first + static_cast<size_t>(j + band) * stored_width + static_cast<size_t>(i + band), level.at(i, j));
  }
}

// The strips of the faces in the packing window, by face: what the bands being packed read.
class WindowStrips final : public BandTexels {
 public:
  explicit WindowStrips(size_t faces) : strips_(faces) {}
  bool holds(size_t face) const { return strips_[face] != nullptr; }
  void hold(size_t face, std::unique_ptr<EdgeStrips> strips) { strips_[face] = std::move(strips); }
  void drop(size_t face) { strips_[face].reset(); }
  const glm::vec4& at(uint32_t face, size_t level, int i, int j) const override {
    if (!strips_[face]) throw std::logic_error("pack_scene: a band read face " + std::to_string(face) + " outside the window");
    return strips_[face]->at(level, i, j);
  }

 private:
  std::vector<std::unique_ptr<EdgeStrips>> strips_;
};

// Guard bands of a scene with deferred textures. A face's band reads the levels of the faces
// across its edges and around its corners, all of which share a vertex with it, and of those only
// strips along their edges (band_read_depths). So the faces are visited one after another; the
// first time the window reaches a face its chain is made, its own texels are packed, the strips
// its neighbours' bands read are kept and the chain is dropped; the strips go once the last face
// reading them is banded. The order is breadth first over faces that share a vertex (each
// connected part in turn), so that the strips held at once are those of a few rings of the mesh
// around the packing front, however the file numbers its faces, and no more than one face's
// chain exists at a time. Each texel is written to its own place: the order changes no result.
void pack_banded_deferred(const Scene& scene, PackedScene& out, const std::vector<size_t>& first_level) {
  const size_t count = scene.faces.size();
  std::vector<std::vector<uint32_t>> faces_at_vertex(scene.positions.size());
  for (size_t f = 0; f < count; ++f)
    for (uint32_t v : scene.faces[f].vertices) faces_at_vertex[v].push_back(static_cast<uint32_t>(f));
  auto readers_of = [&](size_t f) {  // the faces f's band may read: those sharing a vertex with it, f included
    std::vector<uint32_t> around;
    for (uint32_t v : scene.faces[f].vertices) around.insert(around.end(), faces_at_vertex[v].begin(), faces_at_vertex[v].end());
    std::sort(around.begin(), around.end());
    around.erase(std::unique(around.begin(), around.end()), around.end());
    return around;
  };
  std::vector<uint32_t> order;
  order.reserve(count);
  std::vector<bool> queued(count, false);
  for (size_t start = 0; start < count; ++start) {
    if (queued[start]) continue;
    queued[start] = true;
    order.push_back(static_cast<uint32_t>(start));
    for (size_t next = order.size() - 1; next < order.size(); ++next)
      for (uint32_t g : readers_of(order[next]))
        if (!queued[g]) {
          queued[g] = true;
          order.push_back(g);
        }
  }
  std::vector<size_t> last_reader(count, 0);  // position in `order` of the last face reading each face
  for (size_t k = 0; k < count; ++k)
    for (uint32_t g : readers_of(order[k])) last_reader[g] = std::max(last_reader[g], k);
  const std::vector<std::vector<int>> depths = band_read_depths(scene, out.neighbors, out.guard_band);
  WindowStrips window(count);
  std::vector<bool> packed_own(count, false);
  for (size_t k = 0; k < count; ++k) {
    const uint32_t f = order[k];
    const std::vector<uint32_t> around = readers_of(f);
    for (uint32_t g : around) {
      if (packed_own[g]) continue;
      const MipChain made = is_deferred(scene.faces[g].texture) ? face_texture(scene, g) : MipChain{};
      const MipChain& chain = made.levels.empty() ? scene.faces[g].texture : made;
      pack_own_texels(chain, out, g, first_level[g]);
      window.hold(g, std::make_unique<EdgeStrips>(chain, depths[g]));
      packed_own[g] = true;
    }
    const size_t band = static_cast<size_t>(out.guard_band);
    for (size_t l = 0; l < scene.faces[f].texture.levels.size(); ++l) {
      const size_t stored_width = static_cast<size_t>(scene.faces[f].texture.levels[l].width) + 2 * band;
      const size_t first = out.level_offsets[first_level[f] + l];
      for_each_band_texel(scene, out.neighbors, f, static_cast<int>(l), out.guard_band, window,
                          [&](int si, int sj, const glm::vec4& texel) {
                            store_texel(out, first + static_cast<size_t>(sj) * stored_width + static_cast<size_t>(si), texel);
                          });
    }
    for (uint32_t g : around)
      if (last_reader[g] == k) window.drop(g);
  }
}

}  // namespace

void fill_edge_reach(const std::vector<FaceGpu>& faces, std::vector<FaceNeighbors>& neighbors) {
  for (FaceNeighbors& n : neighbors) {
    for (int k = 0; k < 4; ++k) {
      // The faces a lookup reaches across edge k: the neighbour and the diagonal faces past its ends.
      const int across[3] = {n.neighbor[k], n.corner[k], n.corner[(k + 1) % 4]};
      const uint8_t maps[3] = {n.edge_map[k], n.corner_map[k], n.corner_map[(k + 1) % 4]};
      // Edges 0 and 2 are crossed along v, 1 and 3 along u (this face's uv).
      const bool along_v = k % 2 == 0;
      float side = 0.0f, ratio = 0.0f;
      for (int i = 0; i < 3; ++i) {
        if (across[i] < 0) continue;
        if (static_cast<size_t>(across[i]) >= faces.size()) {  // not a face: leave the edge unfilled (never skips)
          side = 0.0f;
          break;
        }
        const FaceGpu& g = faces[static_cast<size_t>(across[i])];
        const bool swapped = (maps[i] & SEAMCL_MAP_SWAP) != 0;  // the other face's u runs along this face's v
        const float side_u = static_cast<float>(swapped ? g.height : g.width);
        const float side_v = static_cast<float>(swapped ? g.width : g.height);
        const float along = along_v ? side_v : side_u, cross = along_v ? side_u : side_v;
        if (!(along >= 1.0f && cross >= 1.0f)) {  // not a valid size: leave the edge unfilled
          side = 0.0f;
          break;
        }
        side = side == 0.0f ? along : std::min(side, along);
        ratio = std::max(ratio, cross / along);  // powers of two: exact
      }
      const uint8_t min_side = encode_reach_side(side), max_side = encode_reach_side(side * ratio);  // powers of two: exact
      // Both or neither: a max side read as 0 would understate the reach.
      const bool stored = min_side != SEAMCL_SIDE_NONE && max_side != SEAMCL_SIDE_NONE;
      n.reach_min_side[k] = stored ? min_side : SEAMCL_SIDE_NONE;
      n.reach_max_side[k] = stored ? max_side : SEAMCL_SIDE_NONE;
    }
  }
}

PackedScene pack_scene(const Scene& scene, TexelFormat format, int guard_band) {
  return pack_scene(scene, format, guard_band, build_adjacency(scene));
}

PackedScene pack_scene(const Scene& scene, TexelFormat format, int guard_band, std::vector<FaceNeighbors> adjacency) {
  if (guard_band < 0 || guard_band > kMaxGuardBand) throw std::invalid_argument("guard band out of range");
  if (!adjacency.empty() && adjacency.size() != scene.faces.size()) throw std::logic_error("pack_scene: adjacency of another scene");
  if (guard_band > 0 && adjacency.size() != scene.faces.size()) throw std::logic_error("pack_scene: guard bands need the adjacency");
  PackedScene out;
  out.format = format;
  out.guard_band = guard_band;
  out.neighbors = std::move(adjacency);
  out.positions.reserve(scene.positions.size());
  for (const glm::vec3& p : scene.positions) out.positions.push_back({{p.x, p.y, p.z, 1.0f}});
  out.faces.reserve(scene.faces.size());
  // Exactly what is stored, bands included: growing by push_back would hold up to 3x meanwhile.
  size_t stored_texels = 0;
  for (const Face& face : scene.faces)
    for (const TextureLevel& level : face.texture.levels)
      stored_texels += (static_cast<size_t>(level.width) + 2 * static_cast<size_t>(guard_band)) *
                       (static_cast<size_t>(level.height) + 2 * static_cast<size_t>(guard_band));
  if (stored_texels > std::numeric_limits<uint32_t>::max() / 4) throw std::length_error("scene textures exceed 2^30 texels");
  // First the tables, from the sizes alone (a level stores (w + 2 band) x (h + 2 band) texels) ...
  std::vector<size_t> first_level(scene.faces.size());
  const size_t band = static_cast<size_t>(guard_band);
  size_t texels = 0, max_levels = 0;
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    const Face& face = scene.faces[f];
    FaceGpu gpu{};
    for (int i = 0; i < 4; ++i) gpu.vertex[i] = face.vertices[i];
    gpu.level_table = static_cast<cl_uint>(out.level_offsets.size());
    gpu.width = face.texture.width();
    gpu.height = face.texture.height();
    gpu.level_count = static_cast<cl_int>(face.texture.levels.size());
    const glm::vec3 n = scene.face_normal(face);
    gpu.normal[0] = n.x;
    gpu.normal[1] = n.y;
    gpu.normal[2] = n.z;
    gpu.reflective = face.roughness >= 0.0f ? static_cast<cl_int>(out.reflective_faces.size()) : -1;
    if (face.roughness >= 0.0f) out.reflective_faces.push_back(reflective_face(scene, face));
    first_level[f] = out.level_offsets.size();
    out.level_offsets.resize(out.level_offsets.size() + face.texture.levels.size());
    max_levels = std::max(max_levels, face.texture.levels.size());
    out.faces.push_back(gpu);
  }
  // Level-major: level l of every face (in face order), then level l + 1. Neighbouring faces'
  // coarse levels, which a scene of many small faces reads, then share cache lines and pages;
  // face-major, a face's whole chain lay between them.
  for (size_t l = 0; l < max_levels; ++l) {
    for (size_t f = 0; f < scene.faces.size(); ++f) {
      const MipChain& chain = scene.faces[f].texture;
      if (l >= chain.levels.size()) continue;
      const TextureLevel& level = chain.levels[l];
      const size_t own = static_cast<size_t>(level.width) * static_cast<size_t>(level.height);
      const size_t stored = (static_cast<size_t>(level.width) + 2 * band) * (static_cast<size_t>(level.height) + 2 * band);
      out.level_offsets[first_level[f] + l] = static_cast<uint32_t>(texels);
      texels += stored;
      out.band_texels += stored - own;
    }
  }
  fill_edge_reach(out.faces, out.neighbors);
  // ... then the texels, faces in parallel, each into its own range: exactly sized up front.
  if (format == TexelFormat::Rgba8) {
    out.texels8.resize(stored_texels);
  } else {
    out.texels32.resize(stored_texels * 4);
  }
  if (guard_band > 0 && has_deferred_textures(scene)) {
    pack_banded_deferred(scene, out, first_level);
  } else {
    // Deferred faces' float chains in flight together at most the packed bytes (one at a time when
    // larger): the peak stays within the packed copy + as much again.
    for_each_face_in_budget(
        scene.faces.size(), [&](size_t f) { pack_face_texels(scene, out, f, first_level[f]); },
        [&](size_t f) { return texture_making_bytes(scene, f); }, out.texture_bytes());
  }
  return out;
}

}  // namespace seamcl
