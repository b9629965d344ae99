// subscan.Camera: the library's pinhole camera, in camera.json's conventions.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>

#include "core/Camera.h"
#include "core/Error.h"
#include "core/SensorView.h"
#include "io/CameraJson.h"
#include "io/JsonText.h"
#include "python/Bindings.h"
#include "python/JsonConversion.h"

namespace py = pybind11;

namespace subscan::python {

UpAxis upAxisArgument(const std::string& up, const CloudData& cloud) {
    try {
        return upAxisForScan(up, cloud.format(), cloud.cloud(), cloud.grid);
    } catch (const Error& error) {
        throw py::value_error(error.what());
    }
}

namespace {

/// The camera if camera.json would accept it (sizes, lens, planes, finite matrices), else
/// ValueError with the library's sentence. The JSON round trip is exact (doubles are written
/// with the digits that read back the same number).
Camera checked(const Camera& camera) {
    try {
        return cameraFromJson(cameraToJson(camera));
    } catch (const Error& error) {
        throw py::value_error(error.what());
    }
}

py::array_t<double> matrixOf(const glm::dmat4& matrix) {
    py::array_t<double> result(std::vector<py::ssize_t>{4, 4});
    auto out = result.mutable_unchecked<2>();
    for (int row = 0; row < 4; ++row) {
        for (int column = 0; column < 4; ++column) {
            out(row, column) = matrix[column][row];  // glm is column-major
        }
    }
    return result;
}

glm::dmat4 matrixArgument(const py::handle& object) {
    const auto array = py::array_t<double, py::array::forcecast>::ensure(object);
    if (!array || array.ndim() != 2 || array.shape(0) != 4 || array.shape(1) != 4) {
        throw py::value_error("the camera's 'view' needs 4 rows of 4 numbers");
    }
    glm::dmat4 matrix;
    for (int row = 0; row < 4; ++row) {
        for (int column = 0; column < 4; ++column) {
            matrix[column][row] = array.at(row, column);
        }
    }
    return matrix;
}

/// Camera.orbit: the CLI's --yaw, --pitch, --distance, --up, --fovy, --width and --height,
/// with the CLI's ranges.
Camera orbit(const CloudData& cloud, double yaw, double pitch, std::optional<double> distance,
             const std::string& up, int width, int height, double fovy, const py::object& center) {
    checkRange(pitch, -90.0, 90.0, "pitch");
    checkRange(fovy, 1.0, 170.0, "fovy");
    checkRange(width, 1, 65536, "width");
    checkRange(height, 1, 65536, "height");
    if (!std::isfinite(yaw)) {
        throw py::value_error("yaw must be finite");
    }
    if (distance && !(*distance > 0.0 && std::isfinite(*distance))) {
        throw py::value_error(fmt::format("distance {} must be positive", *distance));
    }
    OrbitView view;
    view.yawDegrees = yaw;
    view.pitchDegrees = pitch;
    view.distance = distance;
    view.up = upAxisArgument(up, cloud);
    if (!center.is_none()) {
        view.center = vectorArgument(center, "center");
    }
    // As render frames a scan: its points' framing box fills the picture.
    view.framing = Framing::Box;
    view.framed = cloud.framed();
    return checked(orbitCamera(cloud.cloud().bounds, view, width, height, fovy));
}

/// Camera.sensor: viewFromSensor with the CLI's --view sensor choices and ranges.
Camera sensorView(const CloudData& cloud, const py::object& sensorObject, std::optional<int> width,
                  std::optional<int> height, double fovy, const std::string& up) {
    checkRange(fovy, 1.0, 170.0, "fovy");
    checkRange(width.value_or(1), 1, 65536, "width");
    checkRange(height.value_or(1), 1, 65536, "height");
    const UpAxis upAxis = upAxisArgument(up, cloud);
    // As --sensor: a given position overrides what the file says, its grid's camera included.
    const OrganisedGrid noGrid;
    std::optional<SensorPose> pose = cloud.sensor;
    if (!sensorObject.is_none()) {
        pose = SensorPose{vectorArgument(sensorObject, "sensor"), "sensor="};
    }
    std::vector<std::string> warnings;
    Camera camera;
    try {
        camera = viewFromSensor(cloud.cloud(), sensorObject.is_none() ? cloud.grid : noGrid, pose,
                                upAxis, width.value_or(1280), height.value_or(720),
                                width.has_value() || height.has_value(), fovy, warnings);
    } catch (const Error& error) {
        throw py::value_error(error.what());
    }
    warnAll("the cloud", warnings);
    return checked(camera);
}

Camera lookAt(const py::handle& eyeObject, const py::handle& targetObject,
              const py::handle& upObject, int width, int height, double fovy,
              std::optional<double> nearPlane, std::optional<double> farPlane,
              const std::optional<CloudHandle>& cloud) {
    const glm::dvec3 eye = vectorArgument(eyeObject, "eye");
    const glm::dvec3 target = vectorArgument(targetObject, "target");
    const glm::dvec3 up = vectorArgument(upObject, "up");
    if (glm::length(target - eye) == 0.0) {
        throw py::value_error("eye and target are the same point");
    }
    if (glm::length(glm::cross(target - eye, up)) <=
        1e-12 * glm::length(target - eye) * glm::length(up)) {
        throw py::value_error("up is parallel to the line of sight (or zero)");
    }
    Camera camera;
    camera.width = width;
    camera.height = height;
    camera.fovyDegrees = fovy;
    camera.view = glm::lookAt(eye, target, up);
    if (cloud && (*cloud) && (!nearPlane || !farPlane)) {
        // As Camera.orbit: near and far hug the cloud's bounding sphere.
        const Bounds& bounds = (*cloud)->cloud().bounds;
        const double radius = std::max(0.5 * glm::length(bounds.extent()),
                                       1e-9 * (1.0 + glm::length(bounds.center())));
        const double distance = glm::length(bounds.center() - eye);
        const double margin = 0.02 * radius;
        const double farFit = distance + radius + margin;
        camera.farPlane = farPlane.value_or(farFit);
        camera.nearPlane = nearPlane.value_or(std::max(distance - radius - margin, 1e-4 * farFit));
    } else if (nearPlane && farPlane) {
        camera.nearPlane = *nearPlane;
        camera.farPlane = *farPlane;
    } else {
        throw py::value_error("look_at needs near and far, or a cloud to fit them to");
    }
    return checked(camera);
}

Camera cameraFromPythonJson(const py::handle& object) {
    nlohmann::json json;
    if (py::isinstance<py::str>(object)) {
        try {
            json = parseJsonText(object.cast<std::string>());
        } catch (const Error& error) {
            throw py::value_error(error.what());
        }
    } else {
        json = toJson(object, "the camera");
    }
    try {
        return cameraFromJson(json);
    } catch (const Error& error) {
        throw py::value_error(error.what());
    }
}

}  // namespace

void bindCamera(py::module_& module) {
    py::class_<Camera>(module, "Camera", R"doc(
A pinhole camera in camera.json's conventions (docs/cli.md, "Pixel convention"): right-handed,
looking down -Z in view space, Y up; `view` maps the cloud's own coordinates to view space.

Camera(width=1280, height=720, fovy=45.0, near=0.01, far=100.0, view=identity)
Camera.orbit(cloud, yaw=30, pitch=20, ...)   as `subscan render`'s --yaw/--pitch/--distance
Camera.look_at(eye, target, up=(0, 1, 0), ...)
Camera.from_json(text_or_dict), Camera.load(path), camera.to_json(), camera.save(path)

Bad values raise ValueError with the sentence camera.json's reader gives.
)doc")
        .def(py::init([](int width, int height, double fovy, double nearPlane, double farPlane,
                         const py::object& view) {
                 Camera camera;
                 camera.width = width;
                 camera.height = height;
                 camera.fovyDegrees = fovy;
                 camera.nearPlane = nearPlane;
                 camera.farPlane = farPlane;
                 if (!view.is_none()) {
                     camera.view = matrixArgument(view);
                 }
                 return checked(camera);
             }),
             py::arg("width") = 1280, py::arg("height") = 720, py::arg("fovy") = 45.0,
             py::arg("near") = 0.01, py::arg("far") = 100.0, py::arg("view") = py::none())
        .def_static("orbit", &orbit, py::arg("cloud"), py::arg("yaw") = 30.0,
                    py::arg("pitch") = 20.0, py::arg("distance") = py::none(),
                    py::arg("up") = "auto", py::arg("width") = 1280, py::arg("height") = 720,
                    py::arg("fovy") = 45.0, py::arg("center") = py::none(), R"doc(
The camera `subscan render` uses without --camera: orbiting the middle of the cloud's bounds
(or `center`), `yaw` degrees around the up axis, `pitch` degrees above the horizon, at
`distance` (default: the box of its points, 0.1 to 99.9 % per axis, fills 95 % of the picture's
limiting side, centred); up 'auto' is Z for LAS files, -Y for a depth camera's organised grid
in its own frame, else Y (or 'y', 'z', '-y'). Near and far hug the bounding sphere.
)doc")
        .def_static("sensor", &sensorView, py::arg("cloud"), py::arg("sensor") = py::none(),
                    py::arg("width") = py::none(), py::arg("height") = py::none(),
                    py::arg("fovy") = 45.0, py::arg("up") = "auto", R"doc(
The camera of `subscan render --view sensor`: for an organised cloud (a depth camera's PCD) its
own camera, fitted to its grid, at the grid's size unless width or height is given; else from
`sensor` (x, y, z), the PCD VIEWPOINT or the E57 pose, looking at the middle of the points,
width x height (default 1280 x 720) and `fovy` wide. ValueError when the cloud records no
sensor and none is given, or the sensor is more than 20 extents from the points.
)doc")
        .def_static("look_at", &lookAt, py::arg("eye"), py::arg("target"),
                    py::arg("up") = py::make_tuple(0.0, 1.0, 0.0), py::arg("width") = 1280,
                    py::arg("height") = 720, py::arg("fovy") = 45.0, py::arg("near") = py::none(),
                    py::arg("far") = py::none(), py::arg("cloud") = py::none(), R"doc(
A camera at `eye` looking at `target` (both in the cloud's coordinates) with `up` towards the
top of the picture. Give near and far, or a cloud whose bounding sphere they then hug.
)doc")
        .def_static("from_json", &cameraFromPythonJson, py::arg("json"),
                    "A camera from camera.json's text (str) or its dict; ValueError names a "
                    "missing or bad field.")
        .def_static(
            "load",
            [](const py::object& path) {
                const std::string file = pathArgument(path);
                return readCameraFile(file);
            },
            py::arg("path"), "Reads a camera.json file (subscan.Error names the file).")
        .def(
            "to_json", [](const Camera& self) { return cameraToJson(self).dump(2) + "\n"; },
            "camera.json's text, as `render --export-buffers` writes it (`subscan render "
            "--camera` reads it).")
        .def(
            "save",
            [](const Camera& self, const py::object& path) {
                writeCameraFile(pathArgument(path), self);
            },
            py::arg("path"), "Writes camera.json, atomically.")
        .def_property(
            "width", [](const Camera& self) { return self.width; },
            [](Camera& self, int value) {
                Camera changed = self;
                changed.width = value;
                self = checked(changed);
            },
            "Image width in pixels.")
        .def_property(
            "height", [](const Camera& self) { return self.height; },
            [](Camera& self, int value) {
                Camera changed = self;
                changed.height = value;
                self = checked(changed);
            },
            "Image height in pixels.")
        .def_property(
            "fovy", [](const Camera& self) { return self.fovyDegrees; },
            [](Camera& self, double value) {
                Camera changed = self;
                changed.fovyDegrees = value;
                self = checked(changed);
            },
            "Vertical field of view, degrees.")
        .def_property(
            "near", [](const Camera& self) { return self.nearPlane; },
            [](Camera& self, double value) {
                Camera changed = self;
                changed.nearPlane = value;
                self = checked(changed);
            },
            "Near plane distance, scene units.")
        .def_property(
            "far", [](const Camera& self) { return self.farPlane; },
            [](Camera& self, double value) {
                Camera changed = self;
                changed.farPlane = value;
                self = checked(changed);
            },
            "Far plane distance, scene units.")
        .def_property(
            "view", [](const Camera& self) { return matrixOf(self.view); },
            [](Camera& self, const py::object& value) {
                Camera changed = self;
                changed.view = matrixArgument(value);
                self = checked(changed);
            },
            "4×4 float64 (a new array), the cloud's coordinates to view space, row-major as "
            "numpy indexes it: view[row, column].")
        .def_property_readonly(
            "projection", [](const Camera& self) { return matrixOf(self.projection()); },
            "4×4 float64, view space to clip space (OpenGL conventions).")
        .def_property_readonly(
            "eye",
            [](const Camera& self) {
                const glm::dvec3 eye = self.eye();
                return py::array_t<double>(3, &eye.x);
            },
            "The eye position in the cloud's coordinates (3 float64).")
        .def(
            "__eq__",
            [](const Camera& self, const Camera& other) {
                return cameraToJson(self) == cameraToJson(other);
            },
            py::is_operator())
        .def("__repr__", [](const Camera& self) {
            const glm::dvec3 eye = self.eye();
            return fmt::format(
                "<subscan.Camera {}x{}, fovy {:g}°, near {:g}, far {:g}, eye ({:g}, {:g}, {:g})>",
                self.width, self.height, self.fovyDegrees, self.nearPlane, self.farPlane, eye.x,
                eye.y, eye.z);
        });
}

}  // namespace subscan::python
