// sdfc._sdfc: the C++ API (api/) as a Python extension. The package's Python
// side (python/sdfc/) turns its results into the public interface: SceneError,
// the builder, the PNG preview.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <future>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "api/evaluate.h"
#include "api/option_limits.h"
#include "api/render_defaults.h"
#include "api/scene.h"
#include "api/scene_render.h"
#include "driver_compile_level.h"
#include "driver_select.h"
#include "image_io.h"
#include "pipeline_cache.h"
#include "spirv/glsl_to_spirv.h"
#include "spirv/spirv_cache.h"
#include "vk_check.h"
#include "vulkan_context.h"

namespace py = pybind11;
using namespace sdfc;

namespace {

// A keyword's value checked against api/option_limits.h, the table the
// command line's flags use: a Python int or float (numpy's too), within the
// option's range, else ValueError naming it (light_samples=-1 had wrapped to
// 4294967295; bounces=1000, time=nan, voxel_size=nan were taken).
double checkedOption(api::Option option, const py::handle& value) {
  const api::OptionLimit& limit = api::optionLimit(option);
  double v = 0;
  if (PyIndex_Check(value.ptr()) && !PyFloat_Check(value.ptr())) {
    // A huge int becomes inf (refused below) rather than an overflow error.
    const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
    if (!index) throw py::error_already_set();
    v = PyLong_AsDouble(index.ptr());
    if (v == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();
      v = std::numeric_limits<double>::infinity();
    }
  } else if (PyFloat_Check(value.ptr()) || py::hasattr(value, "__float__")) {
    v = py::cast<double>(py::float_(py::reinterpret_borrow<py::object>(value)));
  } else {
    throw py::type_error(std::string(limit.name) + " must be a number, got " +
                         std::string(py::str(py::type::handle_of(value).attr("__name__"))));
  }
  const std::string problem = api::optionProblem(option, v, limit.name);
  if (!problem.empty()) throw py::value_error(problem);
  return v;
}

// One Vulkan device per index for the whole process: creating one costs tens of
// milliseconds, and a notebook renders many times. Never destroyed: a scene's
// renderers may be collected after any exit hook, and must find their device.
std::map<int, std::unique_ptr<ScopedContext>>& contexts() {
  static auto* all = new std::map<int, std::unique_ptr<ScopedContext>>;
  return *all;
}

// Renders run with the GIL released, one at a time: they share the devices
// and each scene's kernels.
std::mutex& renderMutex() {
  static std::mutex m;
  return m;
}

VulkanContext& contextFor(int device) {
  auto& all = contexts();
  auto it = all.find(device);
  if (it == all.end()) {
    ContextOptions options;
    options.device_index = device;
    selectedDriver();  // the loader's variables, before its first call
    it = all.emplace(device, std::make_unique<ScopedContext>(options)).first;
  }
  return it->second->get();
}

std::optional<KernelView> kernelView(const std::string& name) {
  std::optional<KernelView> view = kernelViewFromName(name);
  if (!view || *view == KernelView::All)
    throw py::value_error("view must be one of beauty, normal, steps, depth, albedo, iterations; got '" +
                          name + "'");
  return view;
}

// The (N, 3) float64 points of eval and gradient, or a TypeError / ValueError
// that says what was passed.
// Arrays cross the boundary by numpy's array object (shape, strides, data),
// never by pybind11's reading of a dtype: pybind11 before 2.12 reads a
// dtype's item size from numpy 1's struct layout, and under numpy 2 gets 0,
// so an array it sized itself (a 1-D result) had a stride of 0 and showed
// its first element everywhere (the build tree's module, which links the
// system's pybind11, with numpy 2 from pip: eval gave the first point's
// distance for every point). Every array made here has its strides given,
// and every array in or out is checked to be C-contiguous with the element
// size of its type: a wrong one is an error, never wrong numbers.
template <typename T>
void checkLayout(const py::array& a, const char* what) {
  if (a.size() == 0) return;  // no element to reach: numpy's strides are free
  py::ssize_t step = sizeof(T);
  for (py::ssize_t i = a.ndim(); i-- > 0;) {
    if (a.shape(i) > 1 && a.strides(i) != step)
      throw std::runtime_error(std::string(what) + ": numpy gave an array whose strides are not those of " +
                               std::to_string(sizeof(T)) + "-byte elements in C order; this numpy (" +
                               std::string(py::str(py::module_::import("numpy").attr("__version__"))) +
                               ") and the pybind11 sdfc was built with (" + std::to_string(PYBIND11_VERSION_MAJOR) +
                               "." + std::to_string(PYBIND11_VERSION_MINOR) + ") disagree on its layout");
    step *= a.shape(i);
  }
}

template <typename T>
py::array_t<T> newArray(std::vector<py::ssize_t> shape, const char* what) {
  std::vector<py::ssize_t> strides(shape.size());
  py::ssize_t step = sizeof(T);
  for (size_t i = shape.size(); i-- > 0;) {
    strides[i] = step;
    step *= shape[i];
  }
  py::array_t<T> a(shape, strides);
  checkLayout<T>(a, what);
  return a;
}

py::array_t<double, py::array::c_style> checkedPoints(const py::handle& points) {
  if (!py::isinstance<py::array>(points))
    throw py::type_error("points must be a numpy array of shape (N, 3) and dtype float64, got " +
                         std::string(py::str(py::type::of(points).attr("__name__"))));
  py::array a = py::reinterpret_borrow<py::array>(points);
  if (!a.dtype().is(py::dtype::of<double>()))
    throw py::type_error("points must have dtype float64, got " + std::string(py::str(a.dtype())) +
                         " (convert with points.astype(numpy.float64))");
  if (a.ndim() != 2 || a.shape(1) != 3) {
    std::string shape = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape(i));
    shape += a.ndim() == 1 ? ",)" : ")";
    throw py::value_error("points must have shape (N, 3), got " + shape);
  }
  auto p = py::array_t<double, py::array::c_style>::ensure(a);  // a C-contiguous copy when strided
  if (!p) throw py::error_already_set();
  checkLayout<double>(p, "points");
  return p;
}

class PyScene {
 public:
  explicit PyScene(std::unique_ptr<api::Scene> scene) : scene_(std::move(scene)) {}

  bool ok() const { return scene_->ok(); }
  std::string ioError() const { return scene_->io_error; }
  std::string diagnosticsText() const { return scene_->diagnosticsText(false, kDefaultErrorLimit); }
  std::string path() const { return scene_->compiled.source ? scene_->compiled.source->path : ""; }
  std::string text() const { return scene_->compiled.source ? scene_->compiled.source->text : ""; }

  py::list diagnostics() const {
    py::list out;
    for (const api::DiagnosticRecord& d : scene_->diagnosticRecords()) out.append(record(d));
    return out;
  }

  std::vector<std::string> materials() const {
    std::vector<std::string> names;
    for (size_t i = 0; i < scene_->compiled.scene.materials.size(); ++i) {
      std::string name = scene_->compiled.scene.materials[i].name;
      names.push_back(name.empty() ? "material" + std::to_string(i) : name);
    }
    return names;
  }

  py::tuple size() const {
    return py::make_tuple(scene_->compiled.scene.render.width, scene_->compiled.scene.render.height);
  }

  // Distance, gradient or material at every point, the GIL released.
  py::object field(const py::handle& points, const py::handle& time_arg, const py::handle& threads_arg,
                   const std::string& what) const {
    const double time = checkedOption(api::Option::Time, time_arg);
    const int threads = int(checkedOption(api::Option::Threads, threads_arg));
    auto p = checkedPoints(points);
    const size_t n = size_t(p.shape(0));
    api::EvalBatch batch;
    batch.points = p.data();
    batch.count = n;
    batch.time = time;
    batch.threads = threads;
    py::array result;
    if (what == "distance") {
      auto d = newArray<double>({py::ssize_t(n)}, "eval");
      batch.distance = d.mutable_data();
      result = d;
    } else if (what == "gradient") {
      auto g = newArray<double>({py::ssize_t(n), 3}, "gradient");
      batch.gradient = g.mutable_data();
      result = g;
    } else {
      auto m = newArray<int32_t>({py::ssize_t(n)}, "material");
      batch.material = m.mutable_data();
      result = m;
    }
    {
      py::gil_scoped_release release;
      api::evaluate(scene_->compiled.scene, batch);
    }
    return result;
  }

  std::string glsl(const std::string& view) const {
    return scene_->compile(*kernelView(view), std::nullopt, false).emitted.glsl;
  }

  py::bytes spirv(const std::string& view) const {
    CompiledScene c = scene_->compile(*kernelView(view));
    return py::bytes(reinterpret_cast<const char*>(c.spirv.data()), c.spirv.size() * 4);
  }

  // What `sdfc render` decides from the same options (api/render_defaults.h).
  static RenderRequest renderRequest(const RenderOverrides& o, const std::optional<std::string>& denoise) {
    RenderRequest request;
    request.spp = o.spp;
    request.view = o.view;
    if (denoise) {
      request.denoiser = parseDenoiser(*denoise);
      if (!request.denoiser)
        throw py::value_error("denoise must be one of nlr, nlr-fast, none, bilateral, atrous, svgf, nlm; got '" + *denoise + "'");
    }
    return request;
  }

  // The settings render() would use with these options, and the line that says why.
  py::dict renderSettings(const py::handle& spp, const std::string& view, std::optional<std::string> denoise) const {
    kernelView(view);
    RenderOverrides o;
    if (!spp.is_none()) o.spp = int(checkedOption(api::Option::Spp, spp));
    o.view = viewIdFromName(view);
    const RenderChoice c = chooseRenderSettings(renderRequest(o, denoise), &scene_->compiled.scene.render);
    py::dict d;
    d["spp"] = c.spp;
    d["denoiser"] = std::string(denoiserName(c.denoiser));
    d["denoises"] = c.denoises;
    d["adaptive"] = c.adaptive;
    d["reason"] = c.reason;
    return d;
  }

  // As `sdfc render -o x.exr` with the same settings: the kernel for the device
  // (no bounding volumes on a CPU), the scene's settings overridden field by
  // field, the denoiser (nlr by default), the linear float image.
  py::array_t<float> render(const py::handle& size, const py::handle& spp, const std::string& view,
                            std::optional<std::string> denoise, const py::handle& time, const py::handle& seed,
                            const py::handle& bounces, const py::handle& light_samples, int device,
                            std::optional<py::function> progress) {
    const KernelView kernel = *kernelView(view);
    RenderOverrides o;
    if (!size.is_none()) {
      if (!py::isinstance<py::sequence>(size) || py::len(size) != 2)
        throw py::value_error("size must be (width, height)");
      const py::sequence sides = py::reinterpret_borrow<py::sequence>(size);
      o.width = int(checkedOption(api::Option::Size, sides[0]));
      o.height = int(checkedOption(api::Option::Size, sides[1]));
    }
    if (!spp.is_none()) o.spp = int(checkedOption(api::Option::Spp, spp));
    if (!bounces.is_none()) o.bounces = int(checkedOption(api::Option::Bounces, bounces));
    if (!light_samples.is_none()) o.light_samples = int(checkedOption(api::Option::LightSamples, light_samples));
    o.seed = uint32_t(checkedOption(api::Option::Seed, seed));
    o.time = checkedOption(api::Option::Time, time);
    o.view = viewIdFromName(view);
    ImageOptions image;
    image.denoiser = chooseRenderSettings(renderRequest(o, denoise), &scene_->compiled.scene.render).denoiser;
    const RenderSettings planned = renderSettingsFor(scene_->compiled, o);
    const uint64_t samples = uint64_t(planned.width) * planned.height * (o.view == gpu::kViewBeauty ? planned.spp : 1);
    // The device, the kernel and the render run on a worker that never takes the
    // GIL; this thread imports numpy for the result meanwhile (most of a small
    // first render's time in a new process), then relays each pass's progress
    // and checks for Ctrl-C, which Python notes only in the main thread.
    struct Relay {
      std::mutex m;
      std::condition_variable changed;
      std::vector<std::pair<uint32_t, uint32_t>> passes;  // (samples done, spp)
      bool finished = false;
    } relay;
    std::atomic<bool> interrupt{false};
    uint32_t total = 0;  // worker only
    const ProgressCallback report = [&](const ProgressInfo& info) {
      // Samples over the whole image (renderImage counts the halves together):
      // after each pass and at the end, not during the denoise.
      if (info.stage && !info.finished) return;
      const uint32_t done = info.samples_done;
      std::lock_guard<std::mutex> lock(relay.m);
      relay.passes.emplace_back(std::min(done, total), total);
      relay.changed.notify_one();
    };
    RenderedImage rendered;
    std::exception_ptr failed;
    std::thread worker([&] {
      try {
        std::lock_guard<std::mutex> one_render(renderMutex());
        Kernel& k = kernelFor(device, kernel, o.height, samples);
        const RenderSettings settings = renderSettingsFor(*k.compiled, o);
        total = settings.spp;
        rendered = renderImage(*k.renderer, *k.compiled, settings, image, report, &interrupt);
      } catch (...) {
        failed = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(relay.m);
      relay.finished = true;
      relay.changed.notify_one();
    });
    std::optional<py::error_already_set> error;
    try {
      py::module_::import("numpy");
    } catch (py::error_already_set& e) {
      error.emplace(std::move(e));
      interrupt = true;
    }
    for (bool finished = false; !finished;) {
      std::vector<std::pair<uint32_t, uint32_t>> passes;
      {
        py::gil_scoped_release release;
        std::unique_lock<std::mutex> lock(relay.m);
        relay.changed.wait_for(lock, std::chrono::milliseconds(20),
                               [&] { return relay.finished || !relay.passes.empty(); });
        passes.swap(relay.passes);
        finished = relay.finished;
      }
      if (error) continue;
      if (PyErr_CheckSignals() != 0) {
        error.emplace();
        interrupt = true;
        continue;
      }
      for (const auto& [done, spp_total] : passes) {
        if (!progress) break;
        try {
          (*progress)(done, spp_total);
        } catch (py::error_already_set& e) {
          error.emplace(std::move(e));
          interrupt = true;
          break;
        }
      }
    }
    {
      py::gil_scoped_release release;
      worker.join();
    }
    if (error) throw std::move(*error);
    if (failed) std::rethrow_exception(failed);
    const FloatImage& img = rendered.image();
    auto out = newArray<float>({py::ssize_t(img.height), py::ssize_t(img.width), 3}, "render");
    float* dst = out.mutable_data();
    for (size_t i = 0; i < img.pixelCount(); ++i)
      for (int c = 0; c < 3; ++c) dst[i * 3 + c] = img.rgba[i * 4 + c];
    return out;
  }

  py::tuple mesh(const py::handle& resolution, const py::handle& voxel_size, std::optional<std::vector<double>> box,
                 const py::handle& time, const py::handle& threads) const {
    MeshOptions options;
    options.names = {"box", "box=[x0, y0, z0, x1, y1, z1]", "voxel_size", "resolution"};
    options.resolution = int(checkedOption(api::Option::Resolution, resolution));
    if (!voxel_size.is_none()) options.voxel_size = checkedOption(api::Option::VoxelSize, voxel_size);
    options.time = checkedOption(api::Option::Time, time);
    options.threads = int(checkedOption(api::Option::Threads, threads));
    if (box) {
      if (box->size() != 6) throw py::value_error("box must be [x0, y0, z0, x1, y1, z1]");
      options.box = Aabb{glm::dvec3((*box)[0], (*box)[1], (*box)[2]), glm::dvec3((*box)[3], (*box)[4], (*box)[5])};
    }
    MeshResult result;
    {
      py::gil_scoped_release release;
      result = api::mesh(scene_->compiled.scene, options);
    }
    if (!result.error.empty()) throw py::value_error(result.error);
    const TriangleMesh& m = result.mesh;
    auto vertices = newArray<double>({py::ssize_t(m.positions.size()), 3}, "mesh");
    auto faces = newArray<uint32_t>({py::ssize_t(m.triangles.size()), 3}, "mesh");
    auto materials = newArray<int32_t>({py::ssize_t(m.materials.size())}, "mesh");
    double* v = vertices.mutable_data();
    for (size_t i = 0; i < m.positions.size(); ++i)
      for (int c = 0; c < 3; ++c) v[i * 3 + c] = m.positions[i][c];
    uint32_t* f = faces.mutable_data();
    for (size_t i = 0; i < m.triangles.size(); ++i)
      for (int c = 0; c < 3; ++c) f[i * 3 + c] = m.triangles[i][c];
    std::copy(m.materials.begin(), m.materials.end(), materials.mutable_data());
    return py::make_tuple(vertices, faces, materials);
  }

 private:
  // A kernel compiled for one device, view and march height, with its pipeline.
  struct Kernel {
    std::unique_ptr<CompiledScene> compiled;
    std::unique_ptr<Renderer> renderer;
  };

  // As `sdfc render`: a new device is created beside the compile, the kernel
  // compiled for a CPU device meanwhile and again if the device is a GPU.
  Kernel& kernelFor(int device, KernelView view, std::optional<int> height, uint64_t samples) {
    const auto key = std::make_tuple(device, int(view), height.value_or(-1));
    auto it = kernels_.find(key);
    if (it != kernels_.end()) return it->second;
    CompileOptions options = scene_->options.compile;
    options.emit.view = view;
    if (height) options.emit.march.image_height = *height;
    VulkanContext* context = nullptr;
    Kernel k;
    if (contexts().count(device)) {
      context = &contextFor(device);
      adaptCompileOptionsToDevice(options, context->properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU, false);
      k.compiled = std::make_unique<CompiledScene>(scene_->compileWith(options));
    } else {
      // setenv before the device's thread starts. The process's first device
      // takes `sdfc render`'s choice of the driver's compile level for this
      // render (driver_compile_level.h): few samples compile unoptimised.
      selectedDriver();
      if (contexts().empty()) chooseQuickDriverCompile(samples);
      std::future<VulkanContext*> created = std::async(std::launch::async, [&] { return &contextFor(device); });
      CompileOptions cpu = options;
      adaptCompileOptionsToDevice(cpu, true, false);
      try {
        k.compiled = std::make_unique<CompiledScene>(scene_->compileWith(cpu));
      } catch (...) {
        created.wait();
        throw;
      }
      context = created.get();  // rethrows a device error
      if (context->properties.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU)
        k.compiled = std::make_unique<CompiledScene>(scene_->compileWith(options));
    }
    setPipelineCacheDirectory(sdfcCacheDirectory());
    k.renderer = std::make_unique<Renderer>(*context, *k.compiled);
    k.renderer->compileKernel(viewIdFromName(kernelViewName(view)));
    return kernels_.emplace(key, std::move(k)).first->second;
  }

  static py::dict record(const api::DiagnosticRecord& d) {
    py::dict r;
    r["severity"] = d.severity;
    r["file"] = d.file;
    r["line"] = d.line;
    r["column"] = d.column;
    r["message"] = d.message;
    r["name"] = d.name;
    py::list notes;
    for (const api::DiagnosticRecord& n : d.notes) notes.append(record(n));
    r["notes"] = notes;
    return r;
  }

  std::unique_ptr<api::Scene> scene_;
  std::map<std::tuple<int, int, int>, Kernel> kernels_;
};

api::LoadOptions loadOptions(const std::map<std::string, double>& defines,
                             const std::vector<std::string>& disabled_warnings, bool werror) {
  api::LoadOptions o;
  for (const auto& [name, value] : defines) {
    if (!std::isfinite(value) || std::fabs(value) > std::numeric_limits<float>::max())
      throw py::value_error("define '" + name + "' must be finite in float32");
    o.defines[name] = value;
  }
  o.disabled_warnings = disabled_warnings;
  o.werror = werror;
  // As the command line: kernels from the on-disk SPIR-V cache.
  o.compile.spirv_cache = true;
  return o;
}

}  // namespace

PYBIND11_MODULE(_sdfc, m) {
  m.doc() = "sdfc's C++ API; use the sdfc package, not this module";
  m.attr("__version__") = api::kVersion;
  py::register_exception<RuntimeError>(m, "DeviceError", PyExc_RuntimeError);

  py::class_<PyScene>(m, "Scene")
      .def_property_readonly("ok", &PyScene::ok)
      .def_property_readonly("io_error", &PyScene::ioError)
      .def_property_readonly("diagnostics_text", &PyScene::diagnosticsText)
      .def_property_readonly("diagnostics", &PyScene::diagnostics)
      .def_property_readonly("path", &PyScene::path)
      .def_property_readonly("text", &PyScene::text)
      .def_property_readonly("materials", &PyScene::materials)
      .def_property_readonly("size", &PyScene::size)
      .def("field", &PyScene::field, py::arg("points"), py::arg("time") = 0.0, py::arg("threads") = 0,
           py::arg("what") = "distance")
      .def("glsl", &PyScene::glsl, py::arg("view") = "beauty")
      .def("spirv", &PyScene::spirv, py::arg("view") = "beauty")
      .def("render_settings", &PyScene::renderSettings, py::arg("spp") = py::none(), py::arg("view") = "beauty",
           py::arg("denoise") = py::none())
      .def("render", &PyScene::render, py::arg("size") = py::none(), py::arg("spp") = py::none(),
           py::arg("view") = "beauty", py::arg("denoise") = py::none(), py::arg("time") = 0.0,
           py::arg("seed") = 0, py::arg("bounces") = py::none(), py::arg("light_samples") = py::none(),
           py::arg("device") = -1, py::arg("progress") = py::none())
      .def("mesh", &PyScene::mesh, py::arg("resolution") = 128, py::arg("voxel_size") = py::none(),
           py::arg("box") = py::none(), py::arg("time") = 0.0, py::arg("threads") = 0);

  m.def(
      "driver",
      [] {
        // The same selection as the command line's (runtime/driver_select.h), made
        // now if no render has made it yet; listing the devices loads the driver.
        const DriverSelection& s = selectedDriver();
        py::dict d;
        d["choice"] = driverChoiceName(s.requested);
        d["bundled"] = s.bundled;
        d["manifest"] = s.icd;
        d["reason"] = s.reason;
        py::list devices;
        for (const DeviceInfo& info : listDevices()) {
          py::dict dev;
          dev["index"] = info.index;
          dev["name"] = info.name;
          dev["type"] = deviceTypeName(info.type);
          dev["driver"] = info.driver;
          devices.append(dev);
        }
        d["devices"] = devices;
        return d;
      },
      "The Vulkan driver this process renders with, as `sdfc devices` reports it");
  m.def(
      "option_limits",
      [] {
        py::list out;
        for (const api::OptionLimit& l : api::optionLimits()) {
          py::dict d;
          d["name"] = l.name;
          d["flag"] = l.flag;
          d["python"] = l.python;
          d["whole"] = l.whole;
          d["lo"] = l.lo;
          d["hi"] = l.hi;
          d["open_low"] = l.open_low;
          out.append(d);
        }
        return out;
      },
      "api/option_limits.h's table: every option's range, as every front end checks it");
  m.def(
      "load",
      [](const std::string& path, const std::map<std::string, double>& defines,
         const std::vector<std::string>& disabled_warnings, bool werror) {
        return std::make_unique<PyScene>(api::loadFile(path, loadOptions(defines, disabled_warnings, werror)));
      },
      py::arg("path"), py::arg("defines"), py::arg("disabled_warnings"), py::arg("werror"));
  m.def(
      "parse",
      [](const std::string& text, const std::string& name, const std::map<std::string, double>& defines,
         const std::vector<std::string>& disabled_warnings, bool werror) {
        return std::make_unique<PyScene>(
            api::loadString(text, name, loadOptions(defines, disabled_warnings, werror)));
      },
      py::arg("text"), py::arg("name"), py::arg("defines"), py::arg("disabled_warnings"), py::arg("werror"));
  m.def(
      "read_image",
      [](const std::string& path) {
        FloatImage img = readImage(path);
        auto out = newArray<float>({py::ssize_t(img.height), py::ssize_t(img.width), 3}, "read_image");
        float* dst = out.mutable_data();
        for (size_t i = 0; i < img.pixelCount(); ++i)
          for (int c = 0; c < 3; ++c) dst[i * 3 + c] = img.rgba[i * 4 + c];
        return out;
      },
      py::arg("path"));
  m.def(
      "to_srgb8",
      [](py::array_t<float, py::array::c_style | py::array::forcecast> image) {
        if (image.ndim() != 3 || image.shape(2) != 3) throw py::value_error("image must be (H, W, 3)");
        checkLayout<float>(image, "image");
        FloatImage img(uint32_t(image.shape(1)), uint32_t(image.shape(0)), 1.0f);
        const float* src = image.data();
        for (size_t i = 0; i < img.pixelCount(); ++i)
          for (int c = 0; c < 3; ++c) img.rgba[i * 4 + c] = src[i * 3 + c];
        std::vector<uint8_t> bytes = toSrgb8(img, ToneMap{});
        auto out = newArray<uint8_t>({image.shape(0), image.shape(1), 3}, "to_srgb8");
        std::copy(bytes.begin(), bytes.end(), out.mutable_data());
        return out;
      },
      py::arg("image"));
}
