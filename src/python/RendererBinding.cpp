// subscan.Renderer: the frame pipeline on its own headless OpenGL context.
#include <algorithm>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <epoxy/egl.h>
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "core/Coloring.h"
#include "core/Error.h"
#include "core/NormalEstimation.h"
#include "gpu/GlContext.h"
#include "python/Bindings.h"
#include "render/FrameBuffers.h"
#include "render/Renderer.h"

namespace py = pybind11;

namespace subscan::python {

namespace {

/// Makes a renderer's context current on this thread for one call and releases it afterwards:
/// an EGL context is current on at most one thread, and Python may call a renderer from any
/// thread (the GIL is released while it works), so no context stays current between calls.
class CurrentContext {
  public:
    explicit CurrentContext(GlContext& context) {
        // The thread's bound API decides what eglMakeCurrent(..., EGL_NO_CONTEXT) releases; a
        // thread that did not create the context starts with OpenGL ES.
        eglBindAPI(EGL_OPENGL_API);
        context.makeCurrent();
    }
    ~CurrentContext() {
        eglMakeCurrent(eglGetCurrentDisplay(), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    CurrentContext(const CurrentContext&) = delete;
    CurrentContext& operator=(const CurrentContext&) = delete;
};

/// A float image as a numpy array that owns the vector (no copy): H×W, or H×W×C.
py::array arrayOf(ImageF image) {
    auto* values = new std::vector<float>(std::move(image.values));
    const py::capsule owner(
        values, [](void* pointer) { delete static_cast<std::vector<float>*>(pointer); });
    std::vector<py::ssize_t> shape{image.height, image.width};
    if (image.channels > 1) {
        shape.push_back(image.channels);
    }
    return py::array_t<float>(shape, values->data(), owner);
}

class RendererState {
  public:
    RendererState(const CloudHandle& cloud, bool software, const std::string& color,
                  const std::string& up)
        : cloud_(cloud), up_(upAxisArgument(up, *cloud)) {
        Coloring coloring;
        try {
            coloring = parseColoring(color);
        } catch (const Error& error) {
            throw py::value_error(error.what());
        }
        const py::gil_scoped_release release;
        // The colours `subscan render --color` draws (FrameOptions::applyColoring), made before
        // any GL object, so that a colouring the cloud cannot give leaves nothing to free; the
        // scan's own are drawn from where they are, not copied.
        std::vector<Rgba8> colors;
        const bool ownColors =
            cloud->cloud().hasColors() && (coloring == Coloring::Auto || coloring == Coloring::Rgb);
        if (!ownColors) {
            colors = pointColors(cloud->cloud(), coloring, up_);
        }
        HeadlessContextOptions options;
        options.preferHardware = !software;
        options.debugOutput = glDebugOutputRequested();
        context_ = createHeadlessContext(options);
        const CurrentContext current(*context_);
        // The cloud's own estimate of h and local spacing, the ones the CLI's renderer makes:
        // the same pictures. The renderer reads the Cloud's points in place where the driver
        // allows (the Cloud is immutable and kept alive here): no 160 MB copy for 10 M points.
        renderer_ = std::make_unique<Renderer>(*context_, cloud->cloud(), cloud->pointSpacing(), 0,
                                               PointMemory::Borrow);
        // As Renderer::prepareNormals does for `auto` (the CLI's default), estimated once per
        // Cloud.
        if (const std::vector<glm::vec3>& normals = cloud->estimatedNormals(); !normals.empty()) {
            renderer_->setPointNormals(normals);
        }
        if (!ownColors) {
            renderer_->setColors(colors);
        }
    }
    ~RendererState() {
        try {
            close();
        } catch (...) {  // a context that cannot be made current any more: nothing to free
        }
    }
    RendererState(const RendererState&) = delete;
    RendererState& operator=(const RendererState&) = delete;

    py::array_t<std::uint8_t> render(const std::optional<Camera>& cameraArgument,
                                     const std::optional<std::string>& mode,
                                     const py::object& settingsObject,
                                     std::optional<int> samplesArgument, bool buffers) {
        RenderSettings settings = settingsArgument(settingsObject);
        try {
            if (mode) {
                settings.raster.mode = parseRenderMode(*mode);
            } else if (settingsObject.is_none()) {
                settings.raster.mode = RenderMode::Surface;
            }
        } catch (const Error& error) {
            throw py::value_error(error.what());
        }
        // As `subscan render --samples`: with the filter on and no samples, its picture at rest.
        const int samples =
            samplesArgument.value_or(filtersTemporally(settings) ? kTemporalRestFrames : 1);
        if (samples < 1 || samples > 2048) {
            throw py::value_error(fmt::format("samples {} is outside 1..2048", samples));
        }
        if (samples == 1) {
            settings.temporal.enabled = false;  // one frame: no jitter, nothing to blend
        } else {
            if (!reconstructsSurface(settings.raster.mode) ||
                settings.raster.stage != Stage::Final) {
                throw py::value_error(
                    "samples needs the final picture of the surface or sss mode (the temporal "
                    "filter anti-aliases reconstructed surfaces)");
            }
            settings.temporal.enabled = true;
            settings.temporal.maxFrames = std::max(settings.temporal.maxFrames, samples);
        }
        const Camera camera = cameraArgument ? *cameraArgument : defaultCamera();
        const FrameOutputs outputs = buffers ? FrameOutputs::Everything : FrameOutputs::Picture;

        std::vector<std::uint8_t> rgba;
        {
            const py::gil_scoped_release release;
            const std::lock_guard lock(mutex_);
            requireOpen();
            const CurrentContext current(*context_);
            keptBuffers_ = false;
            // Each call is a picture of its own, as each `subscan render` is: no history of an
            // earlier call blends into it.
            renderer_->restartTemporalFilter();
            for (int index = 0; index < samples; ++index) {
                timings_ = renderer_->render(camera, settings, outputs).passes;
            }
            rgba = renderer_->readImage();
            context_->throwOnErrors("while rendering");
            settings_ = settings;
            keptBuffers_ = buffers;
        }
        py::array_t<std::uint8_t> image(
            std::vector<py::ssize_t>{camera.height, camera.width, py::ssize_t{3}});
        std::uint8_t* out = image.mutable_data();
        const std::size_t pixels = rgba.size() / 4;
        for (std::size_t pixel = 0; pixel < pixels; ++pixel) {
            out[3 * pixel] = rgba[4 * pixel];
            out[3 * pixel + 1] = rgba[4 * pixel + 1];
            out[3 * pixel + 2] = rgba[4 * pixel + 2];
        }
        return image;
    }

    py::dict buffers() {
        std::vector<FrameBuffer> buffers;
        {
            const py::gil_scoped_release release;
            const std::lock_guard lock(mutex_);
            requireOpen();
            if (!keptBuffers_) {
                throw Error(
                    "no buffers: the last render() did not keep them (call render(..., "
                    "buffers=True) first)");
            }
            const CurrentContext current(*context_);
            buffers = readFrameBuffers(*renderer_, settings_);
            context_->throwOnErrors("while reading the buffers back");
        }
        py::dict result;
        for (FrameBuffer& buffer : buffers) {
            result[py::str(buffer.name)] = arrayOf(std::move(buffer.image));
        }
        return result;
    }

    py::dict timings() {
        const std::lock_guard lock(mutex_);
        // Ordered by first appearance; a pass that ran more than once in the frame is summed.
        py::dict result;
        for (const PassTiming& timing : timings_) {
            const py::str name(timing.pass);
            const double before = result.contains(name) ? result[name].cast<double>() : 0.0;
            result[name] = before + timing.milliseconds;
        }
        return result;
    }

    Camera bufferCamera() {
        const std::lock_guard lock(mutex_);
        requireOpen();
        if (!keptBuffers_) {
            throw Error("no buffers: the last render() did not keep them");
        }
        return renderer_->pipelineCamera();
    }

    double spacing() {
        const std::lock_guard lock(mutex_);
        requireOpen();
        return renderer_->spacing();
    }

    std::string openGlRenderer() {
        const std::lock_guard lock(mutex_);
        requireOpen();
        const GlCapabilities& capabilities = context_->capabilities();
        return fmt::format("{} | {} | {}", capabilities.version, capabilities.vendor,
                           capabilities.renderer);
    }

    void close() {
        const std::lock_guard lock(mutex_);
        if (renderer_) {
            const CurrentContext current(*context_);
            renderer_.reset();  // its GL objects need their context current
        }
        context_.reset();
        cloud_.reset();  // only once nothing on the GPU reads its points
        keptBuffers_ = false;
    }

  private:
    void requireOpen() const {
        if (!renderer_) {
            throw Error("the renderer is closed");
        }
    }
    /// `subscan render`'s camera without --camera and options but --up (the renderer's `up`):
    /// 1280×720, yaw 30°, pitch 20°.
    Camera defaultCamera() {
        CloudHandle cloud;
        {
            const py::gil_scoped_release release;  // the lock may wait for a whole frame
            const std::lock_guard lock(mutex_);
            requireOpen();
            cloud = cloud_;
        }
        OrbitView orbit;
        orbit.up = up_;
        orbit.framing = Framing::Box;  // as render frames a scan
        orbit.framed = cloud->framed();
        return orbitCamera(cloud->cloud().bounds, orbit, 1280, 720, 45.0);
    }

    CloudHandle cloud_;  // outlives renderer_, which may read its points in place
    UpAxis up_;          // the axis `up` names: the colours' height and the default camera's
    std::mutex mutex_;   // one call at a time; the GIL is released while a call works
    std::unique_ptr<GlContext> context_;
    std::unique_ptr<Renderer> renderer_;
    RenderSettings settings_;  // the last frame's, for its buffers
    bool keptBuffers_ = false;
    std::vector<PassTiming> timings_;
};

}  // namespace

void bindRenderer(py::module_& module) {
    py::class_<RendererState>(module, "Renderer", R"doc(
The frame pipeline for one cloud, on a headless OpenGL 4.5 context of its own (EGL: a GPU when
there is one, else Mesa's llvmpipe). Several renderers may live in one process. The cloud is
uploaded once; the GIL is released while the renderer works, and one call runs at a time.

    r = subscan.Renderer(cloud)
    image = r.render(camera, mode="surface")         # H×W×3 uint8, sRGB, row 0 at the top
    image = r.render(camera, buffers=True); r.buffers()["depth"]

Renderer(cloud, software=False, color="auto", up="auto"): software=True uses Mesa's software
rasterizer even where a GPU exists (`subscan render --software`); color is what the points'
colour shows, as `subscan render --color`: 'auto' (the scan's colour where it has one, else
height for Z-up data, else a uniform grey), 'rgb', 'intensity', 'height', 'uniform' or
'classification'; up is the axis height runs along, as --up ('auto': z for LAS, LAZ and COPC
files, -y for a depth camera's organised grid in its own frame, y otherwise). close() (or a
with-block) frees the GPU memory now.
)doc")
        .def(py::init<const CloudHandle&, bool, const std::string&, const std::string&>(),
             py::arg("cloud"), py::kw_only(), py::arg("software") = false,
             py::arg("color") = "auto", py::arg("up") = "auto")
        .def("render", &RendererState::render, py::arg("camera") = py::none(),
             py::arg("mode") = py::none(), py::arg("settings") = py::none(), py::kw_only(),
             py::arg("samples") = py::none(), py::arg("buffers") = false, R"doc(
Renders one picture and returns it as an H×W×3 uint8 array (sRGB, row 0 at the top): the
picture `subscan render` writes for the same camera, mode and settings.

camera    a Camera; default: Camera.orbit(cloud) (1280×720, yaw 30°, pitch 20°).
mode      'points', 'points-gl', 'splats', 'surface' or 'sss'; default: the settings' mode
          when settings are given, else 'surface'.
settings  a Settings or a dict in the settings file's layout; default: the defaults.
samples   frames averaged through sub-pixel jittered cameras (as --samples; default 1, or
          32 when the settings turn the temporal filter on).
buffers   keep every buffer of the frame for buffers() (as --export-buffers; slower).
)doc")
        .def("buffers", &RendererState::buffers, R"doc(
The last frame's buffers (render(..., buffers=True)) as float32 arrays, those
`subscan render --export-buffers` writes: 'depth' (H×W, linear depth, +inf where nothing is),
'color' (H×W×3 linear RGB, 0 where nothing is), and in the surface and sss modes 'normals'
(H×W×3, view space), 'radiance' (H×W×3 linear, after scattering in sss), 'mask' (H×W, 1 on the
surface, 0 elsewhere), with single scattering also 'single', 'sigma_s', 'sigma_a'. New arrays.
Their size is buffer_camera's: the picture's, or less at reduced resolution.
)doc")
        .def("timings", &RendererState::timings,
             "Milliseconds per pass of the last frame, in order ({pass: ms}).")
        .def_property_readonly("buffer_camera", &RendererState::bufferCamera,
                               "The camera of the buffers (camera.json of --export-buffers).")
        .def_property_readonly("spacing", &RendererState::spacing,
                               "The point spacing h the screen-space radii are scaled by.")
        .def_property_readonly("opengl", &RendererState::openGlRenderer,
                               "The OpenGL version, vendor and renderer (as `render -v`).")
        .def("close", &RendererState::close,
             "Frees the renderer's GPU memory and context now; later calls raise subscan.Error.")
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](RendererState& self, const py::args&) { self.close(); });
}

}  // namespace subscan::python
