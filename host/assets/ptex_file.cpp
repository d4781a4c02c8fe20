#include <seamcl/assets/ptex_file.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <numeric>
#include <sstream>

#include <zlib.h>

#include <seamcl/core/input_error.h>
#include <seamcl/core/regular_file.h>

namespace seamcl {
namespace {

// The format's fixed sizes (Ptex's PtexIO.h); all integers are little-endian.
constexpr uint32_t kPtexMagic = 'P' | ('t' << 8) | ('e' << 16) | (uint32_t('x') << 24);
constexpr uint64_t kHeaderBytes = 64;
constexpr uint64_t kExtHeaderBytes = 40;  // the most of it this reader knows
constexpr uint64_t kFaceInfoBytes = 20;
constexpr uint64_t kLevelInfoBytes = 16;
constexpr uint64_t kFaceDataHeaderBytes = 4;
constexpr uint64_t kBarrierBytes = 8;      // zeros between the metadata and the large metadata
constexpr uint64_t kTiledPrefixBytes = 6;  // a tiled face: tile size (2 x int8), tile header size (u32)
constexpr uint32_t kBlockSizeMask = 0x3fffffff;

enum Encoding : uint32_t { kConstant = 0, kZipped = 1, kDiffZipped = 2, kTiled = 3 };
enum FaceFlag : uint8_t { kFlagConstant = 1, kFlagHasEdits = 2, kFlagSubface = 8 };
enum MetadataType : uint8_t { kString = 0, kInt8, kInt16, kInt32, kFloat, kDouble };

// deflate compresses at best about 1032:1, so a block that claims to inflate to more than that is
// refused before its output is allocated: decoded sizes stay bounded by the file's own size.
constexpr uint64_t kMaxInflateRatio = 1032;
constexpr uint64_t kInflateSlack = 64;

constexpr size_t kMetadataValuesShown = 8;

uint16_t load_u16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
uint32_t load_u32(const uint8_t* p) {
  return uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24);
}
uint64_t load_u64(const uint8_t* p) { return uint64_t(load_u32(p)) | (uint64_t(load_u32(p + 4)) << 32); }
int32_t load_i32(const uint8_t* p) { return static_cast<int32_t>(load_u32(p)); }
float load_f32(const uint8_t* p) {
  const uint32_t bits = load_u32(p);
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

// a + b, or UINT64_MAX when that overflows: an offset past every file.
uint64_t add_saturated(uint64_t a, uint64_t b) {
  return a > std::numeric_limits<uint64_t>::max() - b ? std::numeric_limits<uint64_t>::max() : a + b;
}

std::string str(uint64_t v) { return std::to_string(v); }

int element_bytes(PtexDataType t) {
  switch (t) {
    case PtexDataType::Uint8: return 1;
    case PtexDataType::Uint16:
    case PtexDataType::Float16: return 2;
    case PtexDataType::Float32: return 4;
  }
  return 1;
}

// IEEE 754 binary16 to float, exactly (every half is a float).
float half_to_float(uint16_t h) {
  const bool negative = (h & 0x8000) != 0;
  const int exponent = (h >> 10) & 0x1f;
  const uint32_t mantissa = h & 0x3ffu;
  float magnitude;
  if (exponent == 0) {
    magnitude = std::ldexp(static_cast<float>(mantissa), -24);  // zero and subnormals
  } else if (exponent == 31) {
    magnitude = mantissa == 0 ? std::numeric_limits<float>::infinity()
                              : std::numeric_limits<float>::quiet_NaN();
  } else {
    const uint32_t bits = (uint32_t(exponent - 15 + 127) << 23) | (mantissa << 13);
    std::memcpy(&magnitude, &bits, sizeof magnitude);
  }
  return negative ? -magnitude : magnitude;
}

// Texels of a full chain (level 0 of 2^ulog2 x 2^vlog2 down to 1x1).
uint64_t chain_texels(int ulog2, int vlog2) {
  uint64_t total = 0;
  for (int k = 0; k <= std::max(ulog2, vlog2); ++k)
    total += (uint64_t(1) << std::max(0, ulog2 - k)) * (uint64_t(1) << std::max(0, vlog2 - k));
  return total;
}

TextureLevel filled_level(int width, int height, glm::vec4 value) {
  TextureLevel level;
  level.width = width;
  level.height = height;
  level.texels.assign(static_cast<size_t>(width) * height, value);
  return level;
}

// One zlib inflater reused for every block (a reset is much cheaper than a new stream).
class Inflater {
 public:
  Inflater() {
    if (inflateInit(&stream_) != Z_OK) throw std::bad_alloc();
  }
  ~Inflater() { inflateEnd(&stream_); }
  Inflater(const Inflater&) = delete;
  Inflater& operator=(const Inflater&) = delete;

  // Inflates `in` into exactly out.size() bytes. Returns an empty string on success, else what is
  // wrong: a stream that is corrupt, cut short, or inflates to fewer or more bytes.
  std::string inflate_exact(std::span<const uint8_t> in, std::span<uint8_t> out) {
    if (in.size() > std::numeric_limits<uInt>::max() || out.size() > std::numeric_limits<uInt>::max())
      return "a zlib block of more than 4 GiB";
    inflateReset(&stream_);
    uint8_t spare = 0;
    stream_.next_in = const_cast<Bytef*>(in.data());
    stream_.avail_in = static_cast<uInt>(in.size());
    stream_.next_out = out.empty() ? &spare : out.data();
    stream_.avail_out = static_cast<uInt>(out.size());
    int result = inflate(&stream_, Z_FINISH);
    if (result != Z_STREAM_END && (result == Z_OK || result == Z_BUF_ERROR) && stream_.avail_out == 0) {
      // Full: the stream must end here, with no byte beyond the expected ones.
      stream_.next_out = &spare;
      stream_.avail_out = 1;
      result = inflate(&stream_, Z_FINISH);
      if (stream_.avail_out == 0)
        return "its zlib stream inflates to more than the " + str(out.size()) + " bytes expected";
    }
    if (result == Z_STREAM_END) {
      if (stream_.total_out != out.size())
        return "its zlib stream inflates to " + str(stream_.total_out) + " bytes, not the " +
               str(out.size()) + " expected";
      return {};
    }
    if (result == Z_MEM_ERROR) throw std::bad_alloc();
    if (result == Z_DATA_ERROR || result == Z_NEED_DICT || result == Z_STREAM_ERROR)
      return std::string("its zlib stream is corrupt (") + (stream_.msg ? stream_.msg : "no message") + ")";
    return "its zlib stream is cut short: " + str(in.size()) + " bytes inflate to only " +
           str(stream_.total_out) + " of the " + str(out.size()) + " expected";
  }

 private:
  z_stream stream_{};
};

struct Header {
  uint32_t version = 0, mesh_type = 0, data_type = 0;
  int32_t alpha_channel = -1;
  uint16_t channels = 0, levels = 0;
  uint32_t faces = 0, ext_header_bytes = 0, face_info_bytes = 0, const_data_bytes = 0,
           level_info_bytes = 0;
  uint64_t level_data_bytes = 0;
  uint32_t metadata_zip_bytes = 0, metadata_bytes = 0;
  // The extended header (zero where the file's is shorter).
  uint32_t large_metadata_header_zip_bytes = 0, large_metadata_header_bytes = 0;
  uint64_t large_metadata_data_bytes = 0, edit_data_bytes = 0, edit_data_position = 0;
  uint32_t minor_version = 0;
  uint16_t u_border_mode = 0, v_border_mode = 0, edge_filter_mode = 0;
};

struct LevelInfo {
  uint64_t data_bytes = 0;
  uint32_t header_bytes = 0;
  uint32_t faces = 0;
  uint64_t position = 0;                // of the level's data in the file
  std::vector<uint32_t> block_headers;  // per face of the level (rfaceid order): size and encoding
  std::vector<uint64_t> block_offsets;  // from the file's start
};

struct MetadataValue {
  uint8_t type = 0;
  std::vector<uint8_t> bytes;
};

// How the file's channels become RGBA.
struct ChannelMap {
  std::array<int, 4> source{-1, -1, -1, -1};  // the file's channel of R, G, B, A; -1: a constant
  std::array<float, 4> fill{0, 0, 0, 1};      // the constant where source is -1
  std::array<bool, 3> premultiplied{};  // R, G, B channels Ptex stores multiplied by alpha in reductions
};

class PtexDecoder {
 public:
  // `owned`, when given, holds `bytes` and keeps them alive as long as the decoder (deferred textures).
  PtexDecoder(std::span<const uint8_t> bytes, const PtexLimits& limits,
              std::shared_ptr<const std::vector<uint8_t>> owned = nullptr)
      : owned_(std::move(owned)), file_(bytes), limits_(limits) {}

  PtexFile decode() {
    read_structure();
    read_textures();
    return std::move(out_);
  }

  // The file's textures deferred: every face is decoded once here to check it (and dropped), and
  // the returned file's texture_source decodes a face again when asked. `decoder` must own its bytes.
  static PtexFile decode_deferred(std::shared_ptr<PtexDecoder> decoder) {
    PtexDecoder& d = *decoder;
    d.read_structure();
    d.metadata_.clear();  // in out_ already, as text and mesh
    d.out_.textures.resize(d.header_.faces);
    for (uint32_t f = 0; f < d.header_.faces; ++f) {
      const MipChain checked = d.face_chain(f);  // throws what an eager read would
      d.out_.textures[f] = deferred_mip_chain(checked.width(), checked.height());
    }
    PtexFile out = d.out_;  // small now: face infos, sizes, metadata text, mesh
    out.texture_source_bytes = d.file_.size();
    d.out_.textures.clear();
    d.out_.metadata.clear();
    d.out_.mesh.reset();
    out.texture_source = [decoder = std::shared_ptr<const PtexDecoder>(std::move(decoder))](size_t face) {
      if (face >= decoder->out_.faces.size()) throw std::out_of_range("ptex texture_source: face out of range");
      return decoder->face_chain(static_cast<uint32_t>(face));
    };
    return out;
  }

 private:
  [[noreturn]] static void fail(const std::string& message) { throw InputError("texture", message); }

  // Bytes [offset, offset + size) of the file, or an error naming `what` when they are not all there.
  std::span<const uint8_t> section(uint64_t offset, uint64_t size, const std::string& what) const {
    if (offset > file_.size() || size > file_.size() - offset)
      fail(what + ": " + str(size) + " bytes at offset " + str(offset) + " run past the end of the file (" +
           str(file_.size()) + " bytes)");
    return file_.subspan(static_cast<size_t>(offset), static_cast<size_t>(size));
  }

  // Everything but the texels: header, face infos, constant data, level tables, metadata, mesh.
  void read_structure() {
    read_header();
    read_face_info();
    read_constant_data();
    read_level_info();
    check_no_edits();
    read_metadata();
    build_mesh();
  }

  std::vector<uint8_t> inflate_block(std::span<const uint8_t> in, uint64_t size, const std::string& what) const {
    if (size > add_saturated(in.size() * kMaxInflateRatio, kInflateSlack))
      fail(what + ": a zlib block of " + str(in.size()) + " bytes cannot inflate to the " + str(size) +
           " bytes expected");
    std::vector<uint8_t> out(static_cast<size_t>(size));
    // One inflater per thread: a deferred file's faces are decoded by the packing threads at once.
    thread_local Inflater inflater;
    if (std::string problem = inflater.inflate_exact(in, out); !problem.empty()) fail(what + ": " + problem);
    return out;
  }

  void read_header() {
    const std::span<const uint8_t> h = section(0, kHeaderBytes, "header");
    if (load_u32(h.data()) != kPtexMagic) fail("header: not a Ptex file (no \"Ptex\" magic number)");
    header_.version = load_u32(h.data() + 4);
    header_.mesh_type = load_u32(h.data() + 8);
    header_.data_type = load_u32(h.data() + 12);
    header_.alpha_channel = load_i32(h.data() + 16);
    header_.channels = load_u16(h.data() + 20);
    header_.levels = load_u16(h.data() + 22);
    header_.faces = load_u32(h.data() + 24);
    header_.ext_header_bytes = load_u32(h.data() + 28);
    header_.face_info_bytes = load_u32(h.data() + 32);
    header_.const_data_bytes = load_u32(h.data() + 36);
    header_.level_info_bytes = load_u32(h.data() + 40);
    header_.minor_version = load_u32(h.data() + 44);  // changes nothing this reader reads
    header_.level_data_bytes = load_u64(h.data() + 48);
    header_.metadata_zip_bytes = load_u32(h.data() + 56);
    header_.metadata_bytes = load_u32(h.data() + 60);

    if (header_.version != 1) fail("header: version " + str(header_.version) + " is not 1, the only Ptex version");
    if (header_.mesh_type == 0) fail("header: a triangle mesh texture; seamcl reads quad meshes only");
    if (header_.mesh_type != 1) fail("header: mesh type " + str(header_.mesh_type) + " is neither 0 (triangles) nor 1 (quads)");
    if (header_.data_type > 3) fail("header: data type " + str(header_.data_type) + " is not 0 to 3 (uint8, uint16, float16, float32)");
    if (header_.channels == 0 || header_.channels > 4)
      fail("header: " + str(header_.channels) + " channels; seamcl reads 1 to 4");
    if (header_.alpha_channel < -1 || header_.alpha_channel >= header_.channels)
      fail("header: alpha channel " + std::to_string(header_.alpha_channel) + " is neither -1 (none) nor a channel (0 to " +
           str(header_.channels - 1u) + ")");
    if (header_.faces == 0) fail("header: the file has no faces");
    if (header_.faces > static_cast<uint32_t>(std::max(0, limits_.max_faces)))
      fail("header: " + str(header_.faces) + " faces, more than the limit of " + std::to_string(limits_.max_faces));
    if (header_.levels == 0) fail("header: the file has no levels (level 0 holds the textures)");
    if (header_.levels > limits_.max_side_log2 + 1)
      fail("header: " + str(header_.levels) + " levels, more than faces of at most 2^" +
           std::to_string(limits_.max_side_log2) + " texels a side can have");
    if (header_.level_info_bytes != header_.levels * kLevelInfoBytes)
      fail("header: level info of " + str(header_.level_info_bytes) + " bytes for " + str(header_.levels) +
           " levels, not " + str(header_.levels * kLevelInfoBytes));

    const uint64_t ext_bytes = std::min<uint64_t>(header_.ext_header_bytes, kExtHeaderBytes);
    std::array<uint8_t, kExtHeaderBytes> ext{};
    const std::span<const uint8_t> stored = section(kHeaderBytes, ext_bytes, "extended header");
    std::copy(stored.begin(), stored.end(), ext.begin());
    header_.u_border_mode = load_u16(ext.data());
    header_.v_border_mode = load_u16(ext.data() + 4);
    header_.edge_filter_mode = load_u16(ext.data() + 6);
    header_.large_metadata_header_zip_bytes = load_u32(ext.data() + 8);
    header_.large_metadata_header_bytes = load_u32(ext.data() + 12);
    header_.large_metadata_data_bytes = load_u64(ext.data() + 16);
    header_.edit_data_bytes = load_u64(ext.data() + 24);
    header_.edit_data_position = load_u64(ext.data() + 32);

    out_.data_type = static_cast<PtexDataType>(header_.data_type);
    out_.channels = header_.channels;
    out_.alpha_channel = header_.alpha_channel;
    element_bytes_ = element_bytes(out_.data_type);
    pixel_bytes_ = element_bytes_ * out_.channels;

    // Colour channels are the file's channels other than alpha, in order: one is grey, two are
    // red and green (blue 0), a fourth is not shown.
    std::vector<int> colour;
    for (int c = 0; c < out_.channels; ++c)
      if (c != out_.alpha_channel) colour.push_back(c);
    for (int o = 0; o < 3; ++o) {
      if (colour.size() == 1) {
        channels_.source[o] = colour[0];
      } else if (o < static_cast<int>(colour.size())) {
        channels_.source[o] = colour[o];
      }
    }
    channels_.source[3] = out_.alpha_channel;
    // Ptex multiplies the channels before alpha by it (all the others when alpha is channel 0).
    for (int o = 0; o < 3; ++o) {
      const int c = channels_.source[o];
      channels_.premultiplied[o] = out_.alpha_channel >= 0 && c >= 0 &&
                                   (out_.alpha_channel == 0 ? c > 0 : c < out_.alpha_channel);
    }

    // The sections follow one another from the end of the extended header.
    face_info_position_ = kHeaderBytes + header_.ext_header_bytes;
    const_data_position_ = face_info_position_ + header_.face_info_bytes;
    level_info_position_ = const_data_position_ + header_.const_data_bytes;
    level_data_position_ = level_info_position_ + header_.level_info_bytes;
    metadata_position_ = add_saturated(level_data_position_, header_.level_data_bytes);
  }

  void read_face_info() {
    const uint32_t faces = header_.faces;
    const std::vector<uint8_t> raw =
        inflate_block(section(face_info_position_, header_.face_info_bytes, "face info"), faces * kFaceInfoBytes,
                      "face info");
    out_.faces.resize(faces);
    face_flags_.assign(faces, 0);
    for (uint32_t f = 0; f < faces; ++f) {
      const uint8_t* p = raw.data() + f * kFaceInfoBytes;
      PtexFaceInfo& info = out_.faces[f];
      info.ulog2 = static_cast<int8_t>(p[0]);
      info.vlog2 = static_cast<int8_t>(p[1]);
      const uint8_t adjacent_edges = p[2];
      const uint8_t flags = p[3];
      const std::string where = "face " + str(f);
      if (info.ulog2 < 0 || info.vlog2 < 0 || info.ulog2 > limits_.max_side_log2 || info.vlog2 > limits_.max_side_log2)
        fail(where + ": size 2^" + std::to_string(info.ulog2) + " x 2^" + std::to_string(info.vlog2) +
             " is not 1 to 2^" + std::to_string(limits_.max_side_log2) + " a side");
      if (flags & kFlagHasEdits) fail(where + ": the face has edits, which seamcl does not read");
      face_flags_[f] = flags;
      info.constant = (flags & kFlagConstant) != 0;
      info.subface = (flags & kFlagSubface) != 0;
      for (int e = 0; e < 4; ++e) {
        const int32_t neighbour = load_i32(p + 4 + 4 * e);
        if (neighbour < -1 || (neighbour >= 0 && static_cast<uint32_t>(neighbour) >= faces))
          fail(where + ": adjacent face " + std::to_string(neighbour) + " of edge " + std::to_string(e) +
               " is neither -1 (none) nor a face (0 to " + str(faces - 1) + ")");
        info.adjacent_faces[e] = neighbour;
        info.adjacent_edges[e] = static_cast<uint8_t>((adjacent_edges >> (2 * e)) & 3);
      }
    }
    // Check the memory the textures will take before any of it is allocated.
    uint64_t texels = 0;
    for (const PtexFaceInfo& info : out_.faces) texels += chain_texels(info.ulog2, info.vlog2);
    if (texels > limits_.max_texels)
      fail("face info: the textures would decode to " + str(texels) + " texels (all levels), more than the limit of " +
           str(limits_.max_texels));

    // The order of faces in reduction levels: largest smaller side first, constant faces as if
    // that side were 2 texels, ties in face order (Ptex's genRfaceids).
    faces_by_reduction_.resize(faces);
    std::iota(faces_by_reduction_.begin(), faces_by_reduction_.end(), 0u);
    auto key = [&](uint32_t f) {
      const PtexFaceInfo& info = out_.faces[f];
      return info.constant ? 1 : std::min(info.ulog2, info.vlog2);
    };
    std::stable_sort(faces_by_reduction_.begin(), faces_by_reduction_.end(),
                     [&](uint32_t a, uint32_t b) { return key(a) > key(b); });
    reduction_rank_.resize(faces);
    for (uint32_t r = 0; r < faces; ++r) reduction_rank_[faces_by_reduction_[r]] = r;
  }

  void read_constant_data() {
    const std::vector<uint8_t> raw = inflate_block(section(const_data_position_, header_.const_data_bytes, "constant data"),
                                                   uint64_t(header_.faces) * pixel_bytes_, "constant data");
    constant_values_.resize(header_.faces);
    for (uint32_t f = 0; f < header_.faces; ++f)
      constant_values_[f] = pixel(raw.data() + size_t(f) * pixel_bytes_, 1, "face " + str(f) + ": constant value");
  }

  void read_level_info() {
    const std::span<const uint8_t> raw = section(level_info_position_, header_.level_info_bytes, "level info");
    if (header_.level_data_bytes > file_.size())
      fail("header: level data of " + str(header_.level_data_bytes) + " bytes is larger than the file (" +
           str(file_.size()) + " bytes)");
    uint64_t position = level_data_position_;
    const uint64_t level_data_end = level_data_position_ + header_.level_data_bytes;
    levels_.resize(header_.levels);
    for (int k = 0; k < header_.levels; ++k) {
      LevelInfo& level = levels_[k];
      const uint8_t* p = raw.data() + k * kLevelInfoBytes;
      level.data_bytes = load_u64(p);
      level.header_bytes = load_u32(p + 8);
      level.faces = load_u32(p + 12);
      level.position = position;
      const std::string where = "level " + std::to_string(k);
      if (level.data_bytes > level_data_end - position)
        fail(where + ": " + str(level.data_bytes) + " bytes run past the level data's end (" +
             str(level_data_end - position) + " bytes left)");
      position += level.data_bytes;
      if (k == 0 ? level.faces != header_.faces : level.faces > header_.faces)
        fail(where + ": holds " + str(level.faces) + " faces, " +
             (k == 0 ? "not the file's " : "more than the file's ") + str(header_.faces));
      if (level.header_bytes > level.data_bytes)
        fail(where + ": a header of " + str(level.header_bytes) + " bytes in " + str(level.data_bytes) +
             " bytes of level data");
      const std::span<const uint8_t> data = section(level.position, level.data_bytes, where);
      const std::vector<uint8_t> headers =
          inflate_block(data.first(level.header_bytes), uint64_t(level.faces) * kFaceDataHeaderBytes, where + " header");
      level.block_headers.resize(level.faces);
      level.block_offsets.resize(level.faces);
      uint64_t offset = level.header_bytes;
      for (uint32_t r = 0; r < level.faces; ++r) {
        const uint32_t face = k == 0 ? r : faces_by_reduction_[r];
        const PtexFaceInfo& info = out_.faces[face];
        const std::string face_where = "face " + str(face) + ", level " + std::to_string(k);
        if (k > 0 && !info.constant && (info.ulog2 < k || info.vlog2 < k))
          fail(face_where + ": a face of 2^" + std::to_string(info.ulog2) + " x 2^" + std::to_string(info.vlog2) +
               " texels has no reduction at this level");
        level.block_headers[r] = load_u32(headers.data() + r * kFaceDataHeaderBytes);
        const uint32_t size = level.block_headers[r] & kBlockSizeMask;
        if (size > level.data_bytes - offset)
          fail(face_where + ": a block of " + str(size) + " bytes runs past the " + str(level.data_bytes - offset) +
               " bytes left in the level");
        level.block_offsets[r] = level.position + offset;
        offset += size;
      }
    }
    if (position != level_data_end)
      fail("level info: the levels hold " + str(position - level_data_position_) + " bytes, the header says " +
           str(header_.level_data_bytes));
  }

  // Edits (incremental updates appended to a file) are refused: only their presence is read.
  void check_no_edits() const {
    if (header_.edit_data_bytes != 0)
      fail("edits: the extended header records " + str(header_.edit_data_bytes) +
           " bytes of edits, which seamcl does not read; write the file again without them");
    uint64_t position = add_saturated(metadata_position_, header_.metadata_zip_bytes);
    position = add_saturated(position, kBarrierBytes);
    position = add_saturated(position, header_.large_metadata_header_zip_bytes);
    position = add_saturated(position, header_.large_metadata_data_bytes);
    const uint64_t start = std::max(position, header_.edit_data_position);
    // Files that record where edits start also record their size; older ones run to the end.
    const uint64_t end = header_.edit_data_position > 0 ? add_saturated(start, header_.edit_data_bytes)
                                                        : std::numeric_limits<uint64_t>::max();
    constexpr uint64_t kEditHeaderBytes = 5;  // type (u8), size (u32)
    if (start >= end || start > file_.size() || file_.size() - start < kEditHeaderBytes) return;
    const uint32_t edit_bytes = load_u32(file_.data() + start + 1);
    if (edit_bytes != 0)
      fail("edits: the file holds edits (an edit of type " + str(file_[start]) + " at offset " + str(start) +
           "), which seamcl does not read; write the file again without them");
  }

  void read_metadata() {
    std::map<std::string, MetadataValue> values;
    uint64_t total = 0;
    auto add_entry = [&](const std::string& key, uint8_t type, std::vector<uint8_t> bytes) {
      const std::string where = "metadata \"" + key + "\"";
      if (type > kDouble) fail(where + ": unknown value type " + str(type));
      static constexpr size_t kSizes[] = {1, 1, 2, 4, 4, 8};
      if (bytes.size() % kSizes[type] != 0)
        fail(where + ": " + str(bytes.size()) + " bytes are not a whole number of values");
      values[key] = MetadataValue{type, std::move(bytes)};
    };
    auto charge = [&](uint64_t bytes, const std::string& where) {
      total += bytes;
      if (total > limits_.max_metadata_bytes)
        fail(where + ": the metadata exceeds the limit of " + str(limits_.max_metadata_bytes) + " bytes");
    };
    // Entries: key size (u8, with its NUL), key, value type (u8), value size (u32), then the value
    // (small entries) or its compressed size (u32; large entries, whose values follow elsewhere).
    auto entries = [&](const std::vector<uint8_t>& raw, bool large, const std::string& where, auto&& on_entry) {
      size_t pos = 0;
      while (pos < raw.size()) {
        const size_t key_bytes = raw[pos++];
        if (key_bytes == 0 || key_bytes > raw.size() - pos) fail(where + ": an entry's key runs past the block");
        const char* key_start = reinterpret_cast<const char*>(raw.data() + pos);
        const std::string key(key_start, std::find(key_start, key_start + key_bytes - 1, '\0'));
        pos += key_bytes;
        const size_t fixed = large ? 9 : 5;
        if (raw.size() - pos < fixed) fail(where + ": entry \"" + key + "\" runs past the block");
        const uint8_t type = raw[pos];
        const uint32_t value_bytes = load_u32(raw.data() + pos + 1);
        const uint32_t zip_bytes = large ? load_u32(raw.data() + pos + 5) : 0;
        pos += fixed;
        if (!large && value_bytes > raw.size() - pos)
          fail(where + ": entry \"" + key + "\": a value of " + str(value_bytes) + " bytes runs past the block");
        on_entry(key, type, value_bytes, zip_bytes, raw.data() + pos);
        if (!large) pos += value_bytes;
      }
    };

    if (header_.metadata_bytes > 0) {
      charge(header_.metadata_bytes, "metadata");
      const std::vector<uint8_t> raw = inflate_block(
          section(metadata_position_, header_.metadata_zip_bytes, "metadata"), header_.metadata_bytes, "metadata");
      entries(raw, false, "metadata",
              [&](const std::string& key, uint8_t type, uint32_t bytes, uint32_t, const uint8_t* value) {
                add_entry(key, type, std::vector<uint8_t>(value, value + bytes));
              });
    }
    if (header_.large_metadata_header_bytes > 0) {
      const uint64_t header_position = add_saturated(add_saturated(metadata_position_, header_.metadata_zip_bytes), kBarrierBytes);
      const std::string where = "large metadata";
      charge(header_.large_metadata_header_bytes, where);
      const std::vector<uint8_t> raw =
          inflate_block(section(header_position, header_.large_metadata_header_zip_bytes, where),
                        header_.large_metadata_header_bytes, where);
      const uint64_t data_position = header_position + header_.large_metadata_header_zip_bytes;
      const std::span<const uint8_t> data = section(data_position, header_.large_metadata_data_bytes, where + " data");
      uint64_t offset = 0;
      entries(raw, true, where,
              [&](const std::string& key, uint8_t type, uint32_t bytes, uint32_t zip_bytes, const uint8_t*) {
                const std::string entry = where + " \"" + key + "\"";
                if (zip_bytes > data.size() - offset)
                  fail(entry + ": a block of " + str(zip_bytes) + " bytes runs past the " + str(data.size() - offset) +
                       " bytes left");
                charge(bytes, entry);
                add_entry(key, type, inflate_block(data.subspan(offset, zip_bytes), bytes, entry));
                offset += zip_bytes;
              });
    }
    for (const auto& [key, value] : values) out_.metadata[key] = metadata_text(value);
    metadata_ = std::move(values);
  }

  static std::string metadata_text(const MetadataValue& value) {
    if (value.type == kString) {
      const char* start = reinterpret_cast<const char*>(value.bytes.data());
      return std::string(start, std::find(start, start + value.bytes.size(), '\0'));
    }
    static constexpr size_t kSizes[] = {1, 1, 2, 4, 4, 8};
    const size_t size = kSizes[value.type];
    const size_t count = value.bytes.size() / size;
    std::ostringstream text;
    for (size_t i = 0; i < std::min(count, kMetadataValuesShown); ++i) {
      const uint8_t* p = value.bytes.data() + i * size;
      if (i > 0) text << ' ';
      switch (value.type) {
        case kInt8: text << int(static_cast<int8_t>(p[0])); break;
        case kInt16: text << static_cast<int16_t>(load_u16(p)); break;
        case kInt32: text << load_i32(p); break;
        case kFloat: text << load_f32(p); break;
        default: {
          const uint64_t bits = load_u64(p);
          double d;
          std::memcpy(&d, &bits, sizeof d);
          text << d;
        }
      }
    }
    if (count > kMetadataValuesShown) text << " ... (" << count << " values)";
    return text.str();
  }

  // The mesh a file may carry: face vertex counts (all 4), vertex indices, positions (x, y, z).
  void build_mesh() {
    static const char* kKeys[] = {"PtexFaceVertCounts", "PtexFaceVertIndices", "PtexVertPositions"};
    int present = 0;
    for (const char* key : kKeys) present += metadata_.count(key) ? 1 : 0;
    if (present == 0) return;
    if (present != 3)
      fail("metadata: a mesh needs all of PtexFaceVertCounts, PtexFaceVertIndices and PtexVertPositions");
    const MetadataValue& counts = metadata_.at(kKeys[0]);
    const MetadataValue& indices = metadata_.at(kKeys[1]);
    const MetadataValue& positions = metadata_.at(kKeys[2]);
    if (counts.type != kInt32 || indices.type != kInt32 || positions.type != kFloat)
      fail("metadata: the mesh's counts and indices must be int32 and its positions float");
    const size_t faces = counts.bytes.size() / 4;
    if (faces != header_.faces)
      fail("metadata: the mesh has " + str(faces) + " faces, the texture " + str(header_.faces));
    for (size_t f = 0; f < faces; ++f) {
      const int32_t n = load_i32(counts.bytes.data() + 4 * f);
      if (n != 4) fail("metadata: mesh face " + str(f) + " has " + std::to_string(n) + " vertices; seamcl reads quads only");
    }
    if (indices.bytes.size() / 4 != 4 * faces)
      fail("metadata: the mesh has " + str(indices.bytes.size() / 4) + " vertex indices, not 4 per face (" +
           str(4 * faces) + ")");
    if (positions.bytes.size() % 12 != 0)
      fail("metadata: PtexVertPositions holds " + str(positions.bytes.size() / 4) + " values, not 3 per vertex");
    PtexMesh mesh;
    mesh.positions.resize(positions.bytes.size() / 12);
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
      const uint8_t* p = positions.bytes.data() + 12 * v;
      mesh.positions[v] = glm::vec3(load_f32(p), load_f32(p + 4), load_f32(p + 8));
      if (!std::isfinite(mesh.positions[v].x) || !std::isfinite(mesh.positions[v].y) ||
          !std::isfinite(mesh.positions[v].z))
        fail("metadata: mesh vertex " + str(v) + " is not finite");
    }
    mesh.faces.resize(faces);
    for (size_t f = 0; f < faces; ++f)
      for (int i = 0; i < 4; ++i) {
        const int32_t index = load_i32(indices.bytes.data() + 4 * (4 * f + i));
        if (index < 0 || static_cast<size_t>(index) >= mesh.positions.size())
          fail("metadata: mesh face " + str(f) + " names vertex " + std::to_string(index) + " of " +
               str(mesh.positions.size()));
        mesh.faces[f][i] = static_cast<uint32_t>(index);
      }
    out_.mesh = std::move(mesh);
  }

  // One value of the file's type as float; integers are divided by their maximum.
  float element(const uint8_t* p) const {
    if (stored_units_) {
      switch (out_.data_type) {
        case PtexDataType::Uint8: return static_cast<float>(p[0]);
        case PtexDataType::Uint16: return static_cast<float>(load_u16(p));
        default: break;
      }
    }
    switch (out_.data_type) {
      case PtexDataType::Uint8: return static_cast<float>(p[0]) * (1.0f / 255.0f);
      case PtexDataType::Uint16: return static_cast<float>(load_u16(p)) * (1.0f / 65535.0f);
      case PtexDataType::Float16: return half_to_float(load_u16(p));
      case PtexDataType::Float32: return load_f32(p);
    }
    return 0.0f;
  }

  // The RGBA of one texel whose channels lie `stride_elements` values apart. Non-finite or huge
  // values are refused (they would reach a render as inf or nan), naming texel (i, j) if given.
  glm::vec4 pixel(const uint8_t* first, size_t stride_elements, const std::string& where, int i = -1,
                  int j = -1) const {
    float channel[4] = {};
    for (int c = 0; c < out_.channels; ++c) {
      channel[c] = element(first + c * stride_elements * element_bytes_);
      if (!(std::fabs(channel[c]) <= limits_.max_texel_magnitude)) {
        const std::string texel =
            i < 0 ? "" : "texel (" + std::to_string(i) + ", " + std::to_string(j) + ") ";
        fail(where + ": " + texel + "channel " + std::to_string(c) + " is " + magnitude_text(channel[c]));
      }
    }
    glm::vec4 rgba;
    if (stored_units_) return glm::vec4(channel[0], channel[1], channel[2], channel[3]);
    for (int o = 0; o < 4; ++o) rgba[o] = channels_.source[o] >= 0 ? channel[channels_.source[o]] : channels_.fill[o];
    return rgba;
  }

  std::string magnitude_text(float v) const {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    std::ostringstream text;
    text << v << ", beyond the limit of " << limits_.max_texel_magnitude;
    return text.str();
  }

  // Decodes one face block (or tile) of 2^ulog2 x 2^vlog2 texels into `dest` at (x0, y0).
  void decode_block(std::span<const uint8_t> block, uint32_t encoding, int ulog2, int vlog2, TextureLevel& dest,
                    int x0, int y0, bool tiles_allowed, const std::string& where) const {
    const int width = 1 << ulog2;
    const int height = 1 << vlog2;
    switch (encoding) {
      case kConstant: {
        if (block.size() != static_cast<size_t>(pixel_bytes_))
          fail(where + ": a constant block of " + str(block.size()) + " bytes, not one texel (" + str(pixel_bytes_) + ")");
        const glm::vec4 value = pixel(block.data(), 1, where);
        for (int j = 0; j < height; ++j)
          std::fill_n(dest.texels.begin() + static_cast<ptrdiff_t>(size_t(y0 + j) * dest.width + x0), width, value);
        return;
      }
      case kZipped:
      case kDiffZipped: {
        const size_t texels = size_t(width) * height;
        std::vector<uint8_t> raw = inflate_block(block, uint64_t(texels) * pixel_bytes_, where);
        // Integer data is stored as differences from the previous value, all channels in a row.
        if (encoding == kDiffZipped && out_.data_type == PtexDataType::Uint8) {
          uint8_t previous = 0;
          for (uint8_t& v : raw) previous = v = static_cast<uint8_t>(v + previous);
        } else if (encoding == kDiffZipped && out_.data_type == PtexDataType::Uint16) {
          uint16_t previous = 0;
          for (size_t i = 0; i < raw.size(); i += 2) {
            previous = static_cast<uint16_t>(load_u16(&raw[i]) + previous);
            raw[i] = static_cast<uint8_t>(previous & 0xff);
            raw[i + 1] = static_cast<uint8_t>(previous >> 8);
          }
        }
        // Channels are stored one after another (planar).
        for (int j = 0; j < height; ++j)
          for (int i = 0; i < width; ++i) {
            const size_t index = size_t(j) * width + i;
            dest.texels[size_t(y0 + j) * dest.width + (x0 + i)] =
                pixel(raw.data() + index * element_bytes_, texels, where, i, j);
          }
        return;
      }
      case kTiled: {
        if (!tiles_allowed) fail(where + ": a tile is itself tiled");
        if (block.size() < kTiledPrefixBytes) fail(where + ": a tiled block of " + str(block.size()) + " bytes");
        const int tile_ulog2 = static_cast<int8_t>(block[0]);
        const int tile_vlog2 = static_cast<int8_t>(block[1]);
        if (tile_ulog2 < 0 || tile_vlog2 < 0 || tile_ulog2 > ulog2 || tile_vlog2 > vlog2)
          fail(where + ": tiles of 2^" + std::to_string(tile_ulog2) + " x 2^" + std::to_string(tile_vlog2) +
               " texels do not fit a face of 2^" + std::to_string(ulog2) + " x 2^" + std::to_string(vlog2));
        const uint32_t header_bytes = load_u32(block.data() + 2);
        if (header_bytes > block.size() - kTiledPrefixBytes)
          fail(where + ": a tile header of " + str(header_bytes) + " bytes runs past the " +
               str(block.size() - kTiledPrefixBytes) + " bytes left in the block");
        const int tiles_u = 1 << (ulog2 - tile_ulog2);
        const int tiles_v = 1 << (vlog2 - tile_vlog2);
        const std::vector<uint8_t> headers = inflate_block(block.subspan(kTiledPrefixBytes, header_bytes),
                                                           uint64_t(tiles_u) * tiles_v * kFaceDataHeaderBytes,
                                                           where + ", tile header");
        size_t offset = kTiledPrefixBytes + header_bytes;
        for (int t = 0; t < tiles_u * tiles_v; ++t) {
          const uint32_t tile_header = load_u32(headers.data() + size_t(t) * kFaceDataHeaderBytes);
          const uint32_t size = tile_header & kBlockSizeMask;
          const std::string tile_where = where + ", tile " + std::to_string(t);
          if (size > block.size() - offset)
            fail(tile_where + ": a block of " + str(size) + " bytes runs past the " + str(block.size() - offset) +
                 " bytes left in the face");
          decode_block(block.subspan(offset, size), tile_header >> 30, tile_ulog2, tile_vlog2, dest,
                       x0 + (t % tiles_u) * (1 << tile_ulog2), y0 + (t / tiles_u) * (1 << tile_vlog2), false,
                       tile_where);
          offset += size;
        }
        return;
      }
      default: break;
    }
  }

  // Level k of a face from its stored block: 2^(ulog2 - k) x 2^(vlog2 - k) texels.
  TextureLevel stored_level(int k, uint32_t rank, const PtexFaceInfo& info, uint32_t face) const {
    const LevelInfo& level = levels_[k];
    const int ulog2 = info.ulog2 - k;
    const int vlog2 = info.vlog2 - k;
    TextureLevel out;
    out.width = 1 << ulog2;
    out.height = 1 << vlog2;
    out.texels.resize(size_t(out.width) * out.height);
    const uint32_t header = level.block_headers[rank];
    const std::span<const uint8_t> block = file_.subspan(level.block_offsets[rank], header & kBlockSizeMask);
    decode_block(block, header >> 30, ulog2, vlog2, out, 0, 0, true,
                 "face " + str(face) + ", level " + std::to_string(k));
    return out;
  }

  // Ptex stores reductions of a texture with alpha premultiplied; seamcl keeps straight alpha.
  void unpremultiply(TextureLevel& level, uint32_t face, int k) const {
    if (out_.alpha_channel < 0) return;
    for (glm::vec4& t : level.texels) {
      if (t.a <= 0.0f) continue;
      for (int o = 0; o < 3; ++o) {
        if (!channels_.premultiplied[o]) continue;
        t[o] /= t.a;
        if (!(std::fabs(t[o]) <= limits_.max_texel_magnitude))
          fail("face " + str(face) + ", level " + std::to_string(k) + ": a texel divided by its alpha is " +
               magnitude_text(t[o]));
      }
    }
  }

  // Face f's whole chain, as PtexFile::textures describes it.
  MipChain face_chain(uint32_t f) const {
    const PtexFaceInfo& info = out_.faces[f];
    MipChain chain;
    const int levels = 1 + std::max(info.ulog2, info.vlog2);
    chain.levels.reserve(levels);
    for (int k = 0; k < levels; ++k) {
      const int width = std::max(1, (1 << info.ulog2) >> k);
      const int height = std::max(1, (1 << info.vlog2) >> k);
      const uint32_t rank = reduction_rank_[f];
      if (info.constant || (width == 1 && height == 1)) {
        // Ptex's 1x1 level is the constant data: the average its writer stored, not a box
        // filter of level 0 (which differs by rounding).
        chain.levels.push_back(filled_level(width, height, constant_values_[f]));
      } else if (k == 0) {
        chain.levels.push_back(stored_level(0, f, info, f));
      } else if (k < header_.levels && rank < levels_[k].faces) {
        chain.levels.push_back(stored_level(k, rank, info, f));
        unpremultiply(chain.levels.back(), f, k);
      } else {
        chain.levels.push_back(box_downsample(chain.levels.back()));
      }
    }
    return chain;
  }


 public:
  // Faces' stored values (PtexStored): levels the file holds, in its units and channel order.
  static PtexStored decode_stored(std::span<const uint8_t> bytes, const PtexLimits& limits) {
    PtexDecoder d(bytes, limits);
    d.stored_units_ = true;
    d.read_structure();
    PtexStored out;
    out.version = d.header_.version;
    out.minor_version = d.header_.minor_version;
    out.mesh_type = d.header_.mesh_type;
    out.levels = d.header_.levels;
    out.u_border_mode = d.header_.u_border_mode;
    out.v_border_mode = d.header_.v_border_mode;
    out.edge_filter_mode = d.header_.edge_filter_mode;
    out.metadata_bytes = d.header_.metadata_bytes;
    const int channels = d.out_.channels;
    out.faces.resize(d.header_.faces);
    for (uint32_t f = 0; f < d.header_.faces; ++f) {
      const PtexFaceInfo& info = d.out_.faces[f];
      PtexStoredFace& face = out.faces[f];
      face.flags = d.face_flags_[f];
      face.constant.assign(channels, 0.0f);
      for (int c = 0; c < channels; ++c) face.constant[c] = d.constant_values_[f][c];
      if (info.constant) continue;
      const uint32_t rank = d.reduction_rank_[f];
      for (int k = 0; k <= std::min(info.ulog2, info.vlog2); ++k) {
        if (k > 0 && !(k < d.header_.levels && rank < d.levels_[k].faces)) break;
        const TextureLevel level = d.stored_level(k, k == 0 ? f : rank, info, f);
        std::vector<float> values(level.texels.size() * channels);
        for (size_t t = 0; t < level.texels.size(); ++t)
          for (int c = 0; c < channels; ++c) values[t * channels + c] = level.texels[t][c];
        face.levels.push_back(std::move(values));
      }
    }
    out.file = std::move(d.out_);
    return out;
  }

 private:

  void read_textures() {
    out_.textures.resize(header_.faces);
    for (uint32_t f = 0; f < header_.faces; ++f) out_.textures[f] = face_chain(f);
  }

  std::shared_ptr<const std::vector<uint8_t>> owned_;  // the bytes file_ views, for a deferred file
  std::span<const uint8_t> file_;
  PtexLimits limits_;
  Header header_;
  int element_bytes_ = 1;
  int pixel_bytes_ = 1;
  ChannelMap channels_;
  uint64_t face_info_position_ = 0, const_data_position_ = 0, level_info_position_ = 0, level_data_position_ = 0,
           metadata_position_ = 0;
  bool stored_units_ = false;  // values in the file's units and channel order (PtexStored)
  std::vector<uint8_t> face_flags_;
  std::vector<uint32_t> faces_by_reduction_;  // face id of each rank in the reduction levels
  std::vector<uint32_t> reduction_rank_;      // each face's rank there
  std::vector<glm::vec4> constant_values_;
  std::vector<LevelInfo> levels_;
  std::map<std::string, MetadataValue> metadata_;
  PtexFile out_;
};

}  // namespace

PtexFile parse_ptex(std::span<const uint8_t> bytes, const PtexLimits& limits, bool defer_textures) {
  if (!defer_textures) return PtexDecoder(bytes, limits).decode();
  auto owned = std::make_shared<const std::vector<uint8_t>>(bytes.begin(), bytes.end());
  return PtexDecoder::decode_deferred(std::make_shared<PtexDecoder>(std::span<const uint8_t>(*owned), limits, owned));
}

PtexFile read_ptex_file(const std::string& path, const PtexLimits& limits, bool defer_textures) {
  // Opened and checked as one file: a FIFO or a device would block the read until something
  // wrote to it; a directory reads as an enormous size.
  RegularFile file(path);
  if (file.refusal() != RegularFile::Refusal::None) throw InputError("texture", path + ": " + file.refusal_text());
  if (file.size() > limits.max_file_bytes)
    throw InputError("texture", path + ": " + str(uint64_t(file.size())) + " bytes, more than the limit of " +
                                    str(limits.max_file_bytes));
  auto bytes = std::make_shared<std::vector<uint8_t>>();
  if (!file.read_all(*bytes, limits.max_file_bytes))
    throw InputError("texture", path + ": cannot be read to its end: " + file.refusal_text());
  if (bytes->size() > limits.max_file_bytes)
    throw InputError("texture", path + ": more than the limit of " + str(limits.max_file_bytes) + " bytes");
  try {
    if (!defer_textures) return parse_ptex(*bytes, limits);
    const std::span<const uint8_t> view(*bytes);
    return PtexDecoder::decode_deferred(std::make_shared<PtexDecoder>(view, limits, std::move(bytes)));
  } catch (const InputError& e) {
    // The message of parse_ptex's errors follows "texture: "; the path goes in front of it.
    const std::string message = std::string(e.what()).substr(e.field().size() + 2);
    throw InputError("texture", path + ": " + message);
  }
}

PtexStored parse_ptex_stored(std::span<const uint8_t> bytes, const PtexLimits& limits) {
  return PtexDecoder::decode_stored(bytes, limits);
}

PtexStored read_ptex_stored(const std::string& path, const PtexLimits& limits) {
  RegularFile file(path);
  if (file.refusal() != RegularFile::Refusal::None) throw InputError("texture", path + ": " + file.refusal_text());
  if (file.size() > limits.max_file_bytes)
    throw InputError("texture", path + ": " + str(uint64_t(file.size())) + " bytes, more than the limit of " +
                                    str(limits.max_file_bytes));
  std::vector<uint8_t> bytes;
  if (!file.read_all(bytes, limits.max_file_bytes))
    throw InputError("texture", path + ": cannot be read to its end: " + file.refusal_text());
  if (bytes.size() > limits.max_file_bytes)
    throw InputError("texture", path + ": more than the limit of " + str(limits.max_file_bytes) + " bytes");
  try {
    return parse_ptex_stored(bytes, limits);
  } catch (const InputError& e) {
    const std::string message = std::string(e.what()).substr(e.field().size() + 2);
    throw InputError("texture", path + ": " + message);
  }
}

uint64_t ptex_texel_count(const PtexFile& file) {
  uint64_t texels = 0;
  for (const MipChain& chain : file.textures)
    for (const TextureLevel& level : chain.levels) texels += static_cast<uint64_t>(level.width) * level.height;
  return texels;
}

}  // namespace seamcl
