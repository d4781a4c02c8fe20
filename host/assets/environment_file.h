// Environment images from files (a scene's "environment": {"file": ..., "layout": ...} or
// {"faces": [...]}): read through OpenImageIO, checked from the header before any pixel is read,
// and handed to host/scene as decoded pixels (environment_image_from_pixels).
#pragma once
#include <string>

#include <seamcl/assets/scene_source.h>
#include <seamcl/scene/environment.h>

namespace seamcl {

// Reads the files `files` names, each resolved by `resolve` relative to `directory` (the scene
// file's). Errors are InputError naming the JSON path (environment.file, environment.faces[2])
// and the file: missing or unreadable, a side over kMaxEnvironmentImageSide, too many texels, a
// size the layout cannot take, a non-finite texel.
EnvironmentImage read_environment_files(const EnvironmentFiles& files, const std::string& directory,
                                        const AssetPathResolver& resolve);

// Reads the files of `environment` when it names some and has no image yet.
void load_environment_files(Environment& environment, const std::string& directory, const AssetPathResolver& resolve);

}  // namespace seamcl
