#include "assets/environment_file.h"

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <vector>

#include <seamcl/core/input_error.h>
#include <seamcl/io/image_io.h>

namespace seamcl {

EnvironmentImage read_environment_files(const EnvironmentFiles& files, const std::string& directory,
                                        const AssetPathResolver& resolve) {
  const bool faces = files.layout == EnvironmentLayout::Faces;
  std::vector<std::string> fields;
  for (size_t k = 0; k < files.names.size(); ++k)
    fields.push_back(files.field + (faces ? ".faces[" + std::to_string(k) + "]" : ".file"));
  std::vector<DecodedImage> images;
  size_t total = 0;
  for (size_t k = 0; k < files.names.size(); ++k) {
    const std::string path = resolve(files.names[k], directory, fields[k]);
    DecodedImage image;
    // Sizes are refused from the header of the file as opened for the read, before its pixels are
    // allocated; the texels afterwards.
    const auto within_limits = [&](const ImageHeader& header) {
      if (header.width < 1 || header.height < 1 || header.width > kMaxEnvironmentImageSide ||
          header.height > kMaxEnvironmentImageSide)
        throw InputError(fields[k], "'" + path + "' is " + std::to_string(header.width) + " x " +
                                        std::to_string(header.height) + "; each side must be in 1.." +
                                        std::to_string(kMaxEnvironmentImageSide));
      total += static_cast<size_t>(header.width) * static_cast<size_t>(header.height);
      if (total > kMaxEnvironmentTexels)
        throw InputError(fields[k], "'" + path + "': the environment's images hold more than " +
                                        std::to_string(kMaxEnvironmentTexels) + " texels");
    };
    try {
      image.pixels = read_image(path, image.width, image.height, within_limits);
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& error) {
      throw InputError(fields[k], error.what());
    }
    images.push_back(std::move(image));
  }
  try {
    return environment_image_from_pixels(files.layout, images, fields);
  } catch (const InputError& error) {
    // Name the file beside the field.
    const size_t k = std::find(fields.begin(), fields.end(), error.field()) - fields.begin();
    const std::string message = std::string(error.what()).substr(error.field().size() + 2);
    if (k < files.names.size()) throw InputError(error.field(), "'" + files.names[k] + "' " + message);
    throw;
  }
}

void load_environment_files(Environment& environment, const std::string& directory, const AssetPathResolver& resolve) {
  if (!environment.files || environment.image) return;
  environment.image = std::make_shared<const EnvironmentImage>(read_environment_files(*environment.files, directory, resolve));
}

}  // namespace seamcl
