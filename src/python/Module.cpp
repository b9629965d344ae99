// The Python module `subscan`: the library from numpy (docs/python.md).
#include <pybind11/pybind11.h>

#include "core/Error.h"
#include "python/Bindings.h"

namespace py = pybind11;

PYBIND11_MODULE(subscan, module) {
    module.doc() = R"doc(
subscan: raw point clouds rendered as lit, translucent surfaces (see docs/python.md).

    import subscan
    cloud = subscan.load("scan.ply")                 # or subscan.Cloud(numpy_points, colors)
    camera = subscan.Camera.orbit(cloud, yaw=30, pitch=20, width=640, height=480)
    image = subscan.Renderer(cloud).render(camera, mode="surface")   # H×W×3 uint8

Errors are subscan.Error (bad files, GPU failures) or ValueError (bad arguments), with the
sentence the command-line tool prints.
)doc";
    module.attr("__version__") = SUBSCAN_VERSION;
    // Derived from Exception: a failure of the data or the machine, with the CLI's sentence.
    py::register_exception<subscan::Error>(module, "Error");
    subscan::python::bindCloud(module);
    subscan::python::bindCamera(module);
    subscan::python::bindSettings(module);
    subscan::python::bindRenderer(module);
    subscan::python::bindAnalysis(module);
}
