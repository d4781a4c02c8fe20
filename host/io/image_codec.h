// The OpenImageIO calls of seamcl behind a small interface, implemented by a module loaded on the
// first image read or written (libseamcl_oiio.so, built from host/io/oiio/). OpenImageIO pulls
// in about 260 shared libraries whose loading costs a process about 0.4 s of CPU at start; a
// render that writes no file, a test that reads no image and `seamcl --help` never pay it.
// Everything seamcl-specific (sRGB encoding, temporary files, the header checks) stays in the
// library; the module only moves pixels between memory and OpenImageIO.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

namespace seamcl {

// The interface's version: a module built from other sources is refused, not called.
inline constexpr const char* kImageCodecAbi = "seamcl-image-codec-1";

enum class StoredPixels { Uint8, Half, Float };

// One image to write, four channels: RGBA bytes for Uint8, RGBA floats (converted by OpenImageIO
// as the file stores them) for Half and Float.
struct ImageLevel {
  int width = 0;
  int height = 0;
  StoredPixels stored = StoredPixels::Float;
  const void* pixels = nullptr;
};

struct ImageWriteOptions {
  std::string compression;  // "zip"; empty: the format's default
  int png_compression_level = -1;  // -1: the format's default
  int tile_size = 0;  // 0: scanlines
  bool mip_texture = false;  // the levels are one MIP chain ("Plain Texture")
  std::vector<std::pair<std::string, std::string>> text_attributes;
};

// A file opened for reading: its header is read, none of its pixels yet.
class ImageSource {
 public:
  virtual ~ImageSource() = default;
  virtual int width() const = 0;
  virtual int height() const = 0;
  virtual int channels() const = 0;
  // The bytes of the pixels as stored.
  virtual uint64_t stored_bytes() const = 0;
  // A string attribute of the header; empty when absent.
  virtual std::string attribute(const std::string& name) const = 0;
  // Channels 0..min(channels, 4)-1 as floats into `out` (width * height pixels, the rest of each
  // pixel untouched), then from sRGB to linear when `to_linear` and the file says it is sRGB (alpha
  // not converted). Throws std::runtime_error naming `path`.
  virtual void read(glm::vec4* out, bool to_linear) = 0;
};

class ImageCodec {
 public:
  virtual ~ImageCodec() = default;
  // Writes `levels` (one image, or a MIP chain with mip_texture) as `format` ("png", "exr", or
  // empty: from the path's extension) to `path`, or into `memory` when it is not null. Throws
  // std::runtime_error with OpenImageIO's message.
  virtual void write(const std::string& path, const std::string& format, const std::vector<ImageLevel>& levels,
                     const ImageWriteOptions& options, std::string* memory) const = 0;
  // Opens `path` (which the caller checked is a regular file). Throws std::runtime_error.
  virtual std::unique_ptr<ImageSource> open(const std::string& path) const = 0;
  // OpenImageIO's ImageBufAlgo::resize of linear RGBA with filter `filter` of `filter_width`
  // output pixels. Throws std::runtime_error.
  virtual std::vector<glm::vec4> resize(const std::vector<glm::vec4>& pixels, int width, int height, int out_width,
                                        int out_height, const std::string& filter, float filter_width) const = 0;
};

// The module's codec, loaded on the first call (thread-safe). Looked for, in order: the path in
// $SEAMCL_OIIO_MODULE (alone, when set); beside the binary that holds the library (the build
// tree's seamcl and tests, a Python package's own copy); in <libdir>/seamcl/ beside that binary's
// folder (an installed seamcl); the build tree's; the configured install prefix's. Throws
// std::runtime_error naming every place looked at and the loader's message when none loads.
const ImageCodec& image_codec();

}  // namespace seamcl
