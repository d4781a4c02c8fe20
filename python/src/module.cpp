// seamcl._seamcl: the library's jobs for Python (the package python/seamcl/ wraps it; docs/python.md).
// A front end like cli/ and server/: it runs the render and compare jobs (host/jobs/) as the
// command line does, in the same order (parse, scene, plan refused beyond the machine, run), and
// answers with the jobs' JSON and the images as numpy arrays that view the C++ buffers. Requests
// and answers cross as JSON text: the job parses the request as it parses the service's body,
// so the names, defaults and errors are the option table's. Jobs run with the GIL released.
#include <array>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>
#include <nlohmann/json.hpp>

#include <seamcl/assets/ptex_displacement.h>
#include <seamcl/assets/scene_source.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/cancelled.h>
#include <seamcl/core/input_error.h>
#include <seamcl/core/over_budget.h>
#include <seamcl/jobs/compare_job.h>
#include <seamcl/jobs/render_job.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include <seamcl/version.h>
#include "native_array.h"
#include "python_control.h"

namespace nb = nanobind;
using nlohmann::json;

namespace seamcl::python {
namespace {

// One ClRuntime per device filter for the life of the process, shared by every job and thread
// (contexts, queues and programs are thread-safe; each job makes its own Renderer), so that a
// kernel variant compiles once per process as in the service. Never destroyed: the OpenCL
// runtime may already be torn down when static destructors run at interpreter exit.
ClRuntime& runtime_for(const std::string& device) {
  static std::mutex mutex;
  static auto* runtimes = new std::map<std::string, ClRuntime*>();
  std::lock_guard<std::mutex> lock(mutex);
  ClRuntime*& runtime = (*runtimes)[device];
  if (!runtime) {
    try {
      runtime = new ClRuntime(device);
    } catch (...) {
      runtimes->erase(device);
      throw;
    }
  }
  return *runtime;
}

// Two compares of one reference at once (two threads) render it once: the second waits, then
// reads the first's cache entry. Striped by the key's hash, so the locks are a fixed few.
std::unique_lock<std::mutex> lock_reference(const std::string& cache_key) {
  static std::array<std::mutex, 16> stripes;
  return std::unique_lock<std::mutex>(stripes[std::hash<std::string>{}(cache_key) % stripes.size()]);
}

const char* type_name(OptionType type) {
  switch (type) {
    case OptionType::Integer: return "integer";
    case OptionType::Number: return "number";
    case OptionType::Boolean: return "boolean";
    case OptionType::String: return "string";
    case OptionType::Choice: return "choice";
    case OptionType::Size: return "size";
    case OptionType::List: return "list";
  }
  return "string";
}

// The table as JSON: what the package makes its keywords, signatures and stubs of.
std::string table_json(const std::string& job) {
  const OptionTable* table = nullptr;
  if (job == "render") table = &render_job_option_table();
  else if (job == "compare") table = &compare_option_table();
  else throw InputError("job", "must be render or compare, got '" + job + "'");
  json out = json::array();
  for (const OptionSpec& spec : *table) {
    json item = {{"key", spec.key}, {"type", type_name(spec.type)}, {"help", spec.help},
                 {"default", spec.default_value}, {"absent", spec.absent}, {"choices", spec.choices},
                 {"integers", spec.integers}, {"schema", option_schema(spec)}};
    if (spec.type == OptionType::Integer || spec.type == OptionType::Number || spec.type == OptionType::Size) {
      item["minimum"] = spec.minimum;
      item["maximum"] = spec.maximum;
    }
    out.push_back(item);
  }
  return out.dump();
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// `seamcl render --json` and its image: (info JSON text, float32 (H, W, 4) image, the address of
// the image's C++ buffer, which the array views).
nb::tuple render(const std::string& request_text, const std::string& device, nb::object progress) {
  const json request = json::parse(request_text);
  PythonControl python_control(std::move(progress));
  RenderRun run;
  json out;
  bool cancelled = false;
  {
    nb::gil_scoped_release release;
    const RenderJob job(request);
    const RenderOptions& options = job.options();
    ClRuntime& runtime = runtime_for(device);
    const auto scene_start = std::chrono::steady_clock::now();
    SceneSourceOptions source;
    source.generator = job.generator_options();
    source.displacement_map = options.displacement_map;
    Scene scene = load_scene_source(options.scene, options.texture, source);
    const double scene_ms = ms_since(scene_start);
    // Refused before it allocates, as the command line refuses it.
    const JobPlan plan = job.plan(scene);
    refuse_beyond_machine(plan, runtime.info());
    Renderer renderer(runtime);
    limit_to_machine(renderer, runtime.info());
    renderer.load_scene(std::move(scene), options.texels);
    JobControl control = python_control.control();
    control.device_byte_limit = renderer.device_byte_limit();
    try {
      run = job.run(runtime, renderer, renderer.scene(), control, true);
    } catch (const Cancelled&) {
      cancelled = true;
    }
    if (!cancelled) {
      out = job.result_json(run, renderer, runtime.device_description());
      out["kernel_build_ms"] = runtime.program_build_ms();
      out["scene_ms"] = scene_ms;
      out["estimate"] = plan.estimate_json(runtime.info().host_unified_memory);
      out["memory"] = to_json(measure_memory(renderer));
    }
  }
  if (cancelled) {
    python_control.rethrow_python_error();
    throw Cancelled("render");
  }
  const auto address = reinterpret_cast<uintptr_t>(run.last.pixels.data());
  nb::object image = rgba_array(std::move(run.last.pixels), run.last.width, run.last.height);
  return nb::make_tuple(out.dump(), image, address);
}

// `seamcl compare --json` and, with `images`, its arrays: (info JSON text, [(image, error
// distances) per result], {reference name: image}, name of the first reference, {msaa: seam mask}).
nb::tuple compare(const std::string& request_text, const std::string& device, const std::string& cache_dir,
                  bool use_cache, nb::object progress, bool images) {
  const json request = json::parse(request_text);
  PythonControl python_control(std::move(progress));
  CompareRun run;
  json out;
  int width = 0, height = 0;
  bool cancelled = false;
  {
    nb::gil_scoped_release release;
    CompareJob job(request);
    job.reference_settings().cache_dir = cache_dir;
    job.reference_settings().use_cache = use_cache;
    if (use_cache) check_reference_cache_dir(cache_dir, "cache");
    ClRuntime& runtime = runtime_for(device);
    SceneSourceOptions source;
    source.generator = job.generator_options();
    source.displacement_map = job.frame().displacement_map;
    const Scene scene = load_scene_source(job.frame().scene, job.frame().texture, source);
    const JobPlan plan = job.plan(scene);
    refuse_beyond_machine(plan, runtime.info());
    JobControl control = python_control.control();
    control.device_byte_limit = device_memory_bound(runtime.info());
    try {
      run = job.run(runtime, scene, control, lock_reference);
    } catch (const Cancelled&) {
      cancelled = true;
    }
    if (!cancelled) {
      out = job.result_json(run, scene, runtime.device_description(), true);
      out["estimate"] = plan.estimate_json(runtime.info().host_unified_memory);
      out["memory"] = {{"peak_rss_bytes", process_memory().peak_rss_bytes}};
      width = job.frame().width;
      height = job.frame().height;
    }
  }
  if (cancelled) {
    python_control.rethrow_python_error();
    throw Cancelled("compare");
  }
  nb::list results;
  nb::dict references, masks;
  std::string first;
  if (images) {
    const ReferenceImage& first_reference = run.targets.first();
    for (ReferenceImage& reference : run.targets.high_res) {
      const std::string name = to_string(reference.kind);
      if (&reference == &first_reference) first = name;
      references[name.c_str()] = rgba_array(std::move(reference.pixels), reference.width, reference.height);
    }
    for (auto& [msaa, reference] : run.targets.seamless_by_rate) {
      const std::string name = "seamless_msaa" + std::to_string(msaa);
      if (&reference == &first_reference) first = name;
      references[name.c_str()] = rgba_array(std::move(reference.pixels), reference.width, reference.height);
    }
    for (auto& [msaa, mask] : run.targets.masks) masks[nb::int_(msaa)] = byte_array(std::move(mask), width, height);
    for (EntryResult& measured : run.measured) {
      nb::object distance = measured.errors ? float_array(std::move(measured.errors->distance), width, height)
                                            : nb::none();
      results.append(nb::make_tuple(rgba_array(std::move(measured.last.pixels), measured.last.width,
                                               measured.last.height),
                                    distance));
    }
  }
  return nb::make_tuple(out.dump(), results, references, first, masks);
}

// A scene as a render would load it (textures deferred): what it is, or InputError naming
// scene / texture / the scene file's JSON path.
std::string describe_scene(const std::string& scene_name, const std::string& texture) {
  nb::gil_scoped_release release;
  SceneSourceOptions source;
  source.generator.defer_textures = true;
  const Scene scene = load_scene_source(scene_name, texture, source);
  return json{{"name", scene.name},
              {"faces", scene.faces.size()},
              {"triangles", scene.triangle_count()},
              {"texels", scene.texel_count()},
              {"orbit", scene.orbit.has_value()},
              {"environment", scene.environment.has_value()},
              {"displacement", scene.displacement != nullptr}}
      .dump();
}

// `seamcl devices`: every OpenCL device, `chosen` marking the one `device` selects.
std::string devices(const std::string& device) {
  nb::gil_scoped_release release;
  const std::string chosen = runtime_for(device).info().name;
  json out = json::array();
  for (const DeviceInfo& d : list_devices()) {
    out.push_back({{"platform", d.platform}, {"name", d.name}, {"type", d.type}, {"version", d.version},
                   {"compute_units", d.compute_units}, {"global_memory_bytes", d.global_memory_bytes},
                   {"host_unified_memory", d.host_unified_memory}, {"chosen", d.name == chosen}});
  }
  return out.dump();
}

std::string scenes() {
  json out = json::array();
  for (const GeneratorInfo& g : scene_generators()) out.push_back({{"name", g.name}, {"description", g.description}});
  return out.dump();
}

// The package's exception classes (seamcl/_errors.py), handed over at import and held for the
// life of the process (no reference is dropped at exit, when the interpreter may be gone).
nb::handle input_error_type, over_budget_type, cancelled_type;

void raise_input_error(nb::handle type, const InputError& error) {
  nb::object value = type(std::string(error.what()), error.field());
  PyErr_SetObject(type.ptr(), value.ptr());
}

void translate(const std::exception_ptr& pointer, void*) {
  try {
    std::rethrow_exception(pointer);
  } catch (const nb::python_error&) {
    throw;
  } catch (const OverBudget& e) {
    raise_input_error(over_budget_type, e);
  } catch (const InputError& e) {
    raise_input_error(input_error_type, e);
  } catch (const Cancelled& e) {
    PyErr_SetString(cancelled_type.ptr(), e.what());
  } catch (const json::exception& e) {
    PyErr_SetString(PyExc_RuntimeError, e.what());
  } catch (const std::exception& e) {
    // OpenCL errors with the call's name and the CL error (and a failed build's log).
    PyErr_SetString(PyExc_RuntimeError, describe_cl_exception(e).c_str());
  }
}

}  // namespace
}  // namespace seamcl::python

NB_MODULE(_seamcl, m) {
  using namespace seamcl::python;
  m.doc() = "seamcl's jobs; use the package seamcl (docs/python.md)";
  m.attr("version") = SEAMCL_VERSION;
  m.def("_bind_errors", [](nb::handle input_error, nb::handle over_budget, nb::handle cancelled) {
    input_error_type = input_error.inc_ref();
    over_budget_type = over_budget.inc_ref();
    cancelled_type = cancelled.inc_ref();
  });
  nb::register_exception_translator(translate);
  m.def("option_table", &table_json, nb::arg("job"));
  m.def("render", &render, nb::arg("request"), nb::arg("device"), nb::arg("progress").none());
  m.def("compare", &compare, nb::arg("request"), nb::arg("device"), nb::arg("cache_dir"), nb::arg("use_cache"),
        nb::arg("progress").none(), nb::arg("images"));
  m.def("describe_scene", &describe_scene, nb::arg("scene"), nb::arg("texture"));
  m.def("devices", &devices, nb::arg("device"));
  m.def("scenes", &scenes);
}
