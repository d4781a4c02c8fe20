// A program that uses seamcl as a library: load a built-in scene, render it with Discard (Toth
// 2013), write a PNG, and print how far Discard's image is from a second method's.
//   seamcl_consumer OUT.png [SCENE] [SECOND_METHOD]
#include <cstdio>
#include <exception>
#include <optional>
#include <string>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/input_error.h>
#include <seamcl/eval/metrics.h>
#include <seamcl/io/image_io.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_json.h>
#include <seamcl/version.h>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s OUT.png [SCENE] [SECOND_METHOD]\n", argv[0]);
    return 2;
  }
  const std::string output = argv[1];
  const std::string scene_name = argc > 2 ? argv[2] : "paper";
  const std::string second_method = argc > 3 ? argv[3] : "clamp";
  try {
    // 1. The device (first GPU, else first CPU; SEAMCL_DEVICE picks another) and the scene.
    seamcl::ClRuntime runtime;
    const seamcl::Scene scene = seamcl::load_scene(scene_name, {});
    seamcl::Renderer renderer(runtime);
    renderer.load_scene(scene);

    // 2. Discard, from the same option names and values as the CLI and the HTTP service.
    const seamcl::RenderOptions discard =
        seamcl::parse_render_options({{"scene", scene_name}, {"method", "discard"}, {"msaa", 4}, {"size", "160x120"}});
    renderer.warm_up(discard);  // builds the program variant now, not inside the timed frame
    const seamcl::RenderResult discard_image = renderer.render(scene.camera, discard);
    seamcl::write_image(output, discard_image.width, discard_image.height, discard_image.pixels);

    // 3. The second method on the same frame, and the distance between the two images.
    seamcl::RenderOptions other = discard;
    const std::optional<seamcl::Method> method = seamcl::parse_method(second_method);
    if (!method) throw seamcl::InputError("SECOND_METHOD", "unknown method '" + second_method + "'");
    other.method = *method;
    const seamcl::RenderResult other_image = renderer.render(scene.camera, other);
    const seamcl::ImageErrors errors = seamcl::compare_images(other_image.pixels, discard_image.pixels);

    std::printf("seamcl %s on %s\n", SEAMCL_VERSION, runtime.device_description().c_str());
    std::printf("wrote %s: %s, discard, %dx%d, %u fragments, %.2f ms\n", output.c_str(), scene_name.c_str(),
                discard_image.width, discard_image.height, discard_image.stats.fragments, discard_image.ms.total);
    std::printf("%s vs discard: mean %.6f max %.6f over %zu pixels\n", second_method.c_str(), errors.all.mean,
                errors.all.max, errors.all.pixels);
    return 0;
  } catch (const seamcl::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", seamcl::describe_cl_exception(e).c_str());
    return 1;
  }
}
