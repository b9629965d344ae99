#include "io/CameraJson.h"

#include <array>

#include <algorithm>
#include <cmath>
#include <fstream>

#include <fmt/format.h>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "io/AtomicFile.h"
#include "io/JsonText.h"

namespace subscan {

namespace {

nlohmann::json rowMajor(const glm::dmat4& matrix) {
    nlohmann::json rows = nlohmann::json::array();
    for (int row = 0; row < 4; ++row) {
        rows.push_back({matrix[0][row], matrix[1][row], matrix[2][row], matrix[3][row]});
    }
    return rows;
}

template <class T>
T required(const nlohmann::json& json, const char* key) {
    if (!json.contains(key)) {
        throw Error(fmt::format("the camera has no '{}'", key));
    }
    try {
        return json.at(key).get<T>();
    } catch (const nlohmann::json::exception&) {
        throw Error(fmt::format("the camera's '{}' has the wrong type", key));
    }
}

/// An optional [x, y] pixel offset; (0, 0) when absent.
glm::dvec2 optionalPixels(const nlohmann::json& json, const char* name) {
    const auto entry = json.find(name);
    if (entry == json.end()) {
        return glm::dvec2(0.0);
    }
    std::array<double, 2> pixels{};
    try {
        pixels = entry->get<std::array<double, 2>>();
    } catch (const nlohmann::json::exception&) {
        throw Error(fmt::format("the camera's '{}' needs 2 numbers", name));
    }
    if (!std::isfinite(pixels[0]) || !std::isfinite(pixels[1])) {
        throw Error(fmt::format("the camera's '{}' holds a non-finite number", name));
    }
    return {pixels[0], pixels[1]};
}

}  // namespace

nlohmann::json cameraToJson(const Camera& camera) {
    nlohmann::json json = {
        {"width", camera.width},
        {"height", camera.height},
        {"fovy_deg", camera.fovyDegrees},
        {"near", camera.nearPlane},
        {"far", camera.farPlane},
        {"view", rowMajor(camera.view)},
        {"projection", rowMajor(camera.projection())},
    };
    if (camera.jitterPixels != glm::dvec2(0.0)) {
        json["jitter_pixels"] = {camera.jitterPixels.x, camera.jitterPixels.y};
    }
    if (camera.principalOffsetPixels != glm::dvec2(0.0)) {
        json["principal_offset_pixels"] = {camera.principalOffsetPixels.x,
                                           camera.principalOffsetPixels.y};
    }
    return json;
}

Camera cameraFromJson(const nlohmann::json& json) {
    if (!json.is_object()) {
        throw Error("the camera is not a JSON object");
    }
    Camera camera;
    for (const char* key : {"width", "height"}) {
        // 640.0 is 640 (a script that divided wrote it so); 33.5 is no size.
        if (json.contains(key) && json.at(key).is_number_float()) {
            const double value = json.at(key).get<double>();
            if (value != std::floor(value)) {
                throw Error(fmt::format("the camera's '{}' {} is not a whole number", key, value));
            }
        }
    }
    camera.width = required<int>(json, "width");
    camera.height = required<int>(json, "height");
    camera.fovyDegrees = required<double>(json, "fovy_deg");
    camera.nearPlane = required<double>(json, "near");
    camera.farPlane = required<double>(json, "far");
    if (camera.width < 1 || camera.height < 1 || camera.width > 65536 || camera.height > 65536) {
        throw Error(
            fmt::format("the camera size {}x{} is outside 1..65536", camera.width, camera.height));
    }
    if (!(camera.fovyDegrees > 0.0 && camera.fovyDegrees < 180.0)) {
        throw Error(
            fmt::format("the camera's fovy_deg {} is outside (0, 180)", camera.fovyDegrees));
    }
    if (!(camera.nearPlane > 0.0 && camera.farPlane > camera.nearPlane &&
          std::isfinite(camera.farPlane))) {
        throw Error("the camera needs 0 < near < far (finite)");
    }
    const auto rows = required<std::vector<std::vector<double>>>(json, "view");
    if (rows.size() != 4) {
        throw Error("the camera's 'view' needs 4 rows of 4 numbers");
    }
    for (int row = 0; row < 4; ++row) {
        if (rows[static_cast<std::size_t>(row)].size() != 4) {
            throw Error("the camera's 'view' needs 4 rows of 4 numbers");
        }
        for (int column = 0; column < 4; ++column) {
            const double value =
                rows[static_cast<std::size_t>(row)][static_cast<std::size_t>(column)];
            if (!std::isfinite(value)) {
                throw Error("the camera's 'view' holds a non-finite number");
            }
            camera.view[column][row] = value;
        }
    }
    // A rigid motion: a rotation and a translation. Anything else (a scale, a shear, a
    // projective last row) would be drawn as a distorted picture, not refused. The bound allows
    // a view printed with 4 decimals (numpy's and MATLAB's short formats), whose picture is
    // off by about 1e-4 of its size, and refuses any scale or shear of a thousandth or more.
    constexpr double kRigid = 1e-3;
    const glm::dmat3 rotation(camera.view);
    const glm::dmat3 product = glm::transpose(rotation) * rotation;
    bool rigid = glm::determinant(rotation) > 0.0;
    for (int column = 0; column < 3; ++column) {
        for (int row = 0; row < 3; ++row) {
            rigid = rigid && std::abs(product[column][row] - (row == column ? 1.0 : 0.0)) <= kRigid;
        }
    }
    if (!rigid || glm::dvec4(camera.view[0][3], camera.view[1][3], camera.view[2][3],
                             camera.view[3][3]) != glm::dvec4(0.0, 0.0, 0.0, 1.0)) {
        throw Error(
            "the camera's 'view' is not a rigid motion (a rotation, then a translation, with the "
            "last row 0 0 0 1)");
    }
    camera.jitterPixels = optionalPixels(json, "jitter_pixels");
    camera.principalOffsetPixels = optionalPixels(json, "principal_offset_pixels");
    // The projection follows from the size, fovy_deg, near, far and the offsets; one that says
    // otherwise (another tool's, an orthographic one, an edited one) would be ignored unseen.
    if (json.contains("projection")) {
        const auto given = required<std::vector<std::vector<double>>>(json, "projection");
        const glm::dmat4 derived = camera.projection();
        bool agrees = given.size() == 4;
        for (std::size_t row = 0; agrees && row < 4; ++row) {
            agrees = given[row].size() == 4;
            for (std::size_t column = 0; agrees && column < 4; ++column) {
                const double expected = derived[static_cast<int>(column)][static_cast<int>(row)];
                // Relative to the entry's size: a file printed with 4 decimals agrees, another
                // field of view, size, near plane or kind of projection does not.
                agrees = std::abs(given[row][column] - expected) <=
                         kRigid * std::max(1.0, std::abs(expected));
            }
        }
        if (!agrees) {
            throw Error(
                "the camera's 'projection' is not the one its width, height, fovy_deg, near, far "
                "and pixel offsets give (subscan derives it from them): remove it or make it "
                "match");
        }
    }
    return camera;
}

void writeCameraFile(const std::filesystem::path& path, const Camera& camera) {
    writeFileAtomically(path, cameraToJson(camera).dump(2) + "\n");
}

Camera readCameraFile(const std::filesystem::path& path) {
    std::ifstream stream(path);
    if (!stream) {
        throw Error(fmt::format("{}: cannot open the camera file", path.string()));
    }
    try {
        return cameraFromJson(parseJsonText(stream));
    } catch (const Error& error) {
        throw Error(fmt::format("{}: {}", path.string(), error.what()));
    }
}

}  // namespace subscan
