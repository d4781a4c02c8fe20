// The ImageCodec of host/io/image_codec.h through OpenImageIO: the module libseamcl_oiio.so. It
// links nothing of seamcl's library (which loads it), so it uses the interface's header alone.
#include "io/image_codec.h"

#include <stdexcept>
#include <string>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

namespace seamcl {
namespace {

OIIO::TypeDesc stored_type(StoredPixels stored) {
  switch (stored) {
    case StoredPixels::Uint8: return OIIO::TypeDesc::UINT8;
    case StoredPixels::Half: return OIIO::TypeDesc::HALF;
    case StoredPixels::Float: return OIIO::TypeDesc::FLOAT;
  }
  throw std::logic_error("unknown stored pixel type");
}

// OpenImageIO's error text, or what is known without one: some readers fail without a message (a
// PPM shorter than its header says).
std::string reason(const std::string& error) {
  return error.empty() ? "the reader failed without a message (a damaged or truncated file?)" : error;
}

class OiioSource final : public ImageSource {
 public:
  OiioSource(std::unique_ptr<OIIO::ImageInput> input, std::string path)
      : input_(std::move(input)), spec_(input_->spec()), path_(std::move(path)) {}

  int width() const override { return spec_.width; }
  int height() const override { return spec_.height; }
  int channels() const override { return spec_.nchannels; }
  uint64_t stored_bytes() const override { return spec_.image_bytes(true); }
  std::string attribute(const std::string& name) const override { return spec_.get_string_attribute(name); }

  void read(glm::vec4* out, bool to_linear) override {
    const OIIO::stride_t pixel_stride = sizeof(glm::vec4);
    const int channels = std::min(spec_.nchannels, 4);
    if (!input_->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, out, pixel_stride, pixel_stride * spec_.width))
      throw std::runtime_error("cannot read " + path_ + ": " + reason(input_->geterror()));
    input_->close();
    if (to_linear && spec_.get_string_attribute("oiio:ColorSpace") == "sRGB") {
      OIIO::ImageBuf in_place(OIIO::ImageSpec(spec_.width, spec_.height, 4, OIIO::TypeDesc::FLOAT), out);
      if (!OIIO::ImageBufAlgo::colorconvert(in_place, in_place, "sRGB", "linear"))
        throw std::runtime_error("cannot convert " + path_ + " to linear: " + in_place.geterror());
    }
  }

 private:
  std::unique_ptr<OIIO::ImageInput> input_;
  OIIO::ImageSpec spec_;
  std::string path_;
};

class OiioCodec final : public ImageCodec {
 public:
  void write(const std::string& path, const std::string& format, const std::vector<ImageLevel>& levels,
             const ImageWriteOptions& options, std::string* memory) const override {
    if (levels.empty()) throw std::logic_error("an image write needs a level");
    auto output = OIIO::ImageOutput::create(format.empty() ? path : format);
    if (!output) throw std::runtime_error("no writer for " + path + ": " + OIIO::geterror());
    if (options.mip_texture && (!output->supports("mipmap") || !output->supports("tiles")))
      throw std::runtime_error(path + ": format lacks MIP-mapped tiles");
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    for (size_t l = 0; l < levels.size(); ++l) {
      const ImageLevel& level = levels[l];
      OIIO::ImageSpec spec(level.width, level.height, 4, stored_type(level.stored));
      if (options.tile_size > 0) {
        spec.tile_width = options.tile_size;
        spec.tile_height = options.tile_size;
      }
      if (options.mip_texture) spec.attribute("textureformat", "Plain Texture");
      if (!options.compression.empty()) spec.attribute("compression", options.compression);
      if (options.png_compression_level >= 0) spec.attribute("png:compressionLevel", options.png_compression_level);
      for (const auto& [name, value] : options.text_attributes) spec.attribute(name, value);
      if (memory != nullptr) {
        // The attribute holds a pointer: OpenImageIO reads the address of our pointer to the proxy.
        void* proxy_address = &proxy;
        spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy_address);
      }
      const auto mode = l == 0 ? OIIO::ImageOutput::Create : OIIO::ImageOutput::AppendMIPLevel;
      const OIIO::TypeDesc given = level.stored == StoredPixels::Uint8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT;
      if (!output->open(path, spec, mode) || !output->write_image(given, level.pixels))
        throw std::runtime_error("cannot write " + path + ": " + output->geterror());
    }
    if (!output->close()) throw std::runtime_error("cannot write " + path + ": " + output->geterror());
    if (memory != nullptr) memory->assign(bytes.begin(), bytes.end());
  }

  std::unique_ptr<ImageSource> open(const std::string& path) const override {
    auto input = OIIO::ImageInput::open(path);
    if (!input) throw std::runtime_error("cannot read " + path + ": " + reason(OIIO::geterror()));
    return std::make_unique<OiioSource>(std::move(input), path);
  }

  std::vector<glm::vec4> resize(const std::vector<glm::vec4>& pixels, int width, int height, int out_width,
                                int out_height, const std::string& filter, float filter_width) const override {
    // Wraps the caller's pixels without copying (ImageBuf only reads them here).
    const OIIO::ImageBuf src(OIIO::ImageSpec(width, height, 4, OIIO::TypeDesc::FLOAT),
                             const_cast<glm::vec4*>(pixels.data()));
    OIIO::ImageBuf dst(OIIO::ImageSpec(out_width, out_height, 4, OIIO::TypeDesc::FLOAT));
    if (!OIIO::ImageBufAlgo::resize(dst, src, filter, filter_width))
      throw std::runtime_error("resize (" + filter + ") failed: " + dst.geterror());
    std::vector<glm::vec4> out(static_cast<size_t>(out_width) * static_cast<size_t>(out_height));
    if (!dst.get_pixels(OIIO::ROI(0, out_width, 0, out_height, 0, 1, 0, 4), OIIO::TypeDesc::FLOAT, out.data()))
      throw std::runtime_error("resize (" + filter + "): " + dst.geterror());
    return out;
  }
};

}  // namespace
}  // namespace seamcl

// The module's one entry point: the codec when the caller was built against the same interface.
extern "C" __attribute__((visibility("default"))) const seamcl::ImageCodec* seamcl_image_codec(const char* abi) {
  static const seamcl::OiioCodec codec;
  return std::string(abi) == seamcl::kImageCodecAbi ? &codec : nullptr;
}
