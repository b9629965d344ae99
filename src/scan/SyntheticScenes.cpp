#include "scan/SyntheticScenes.h"

#include <charconv>
#include <cmath>
#include <numbers>
#include <string>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

namespace {

/// Points on the unit sphere by the Fibonacci lattice: nearly uniform, deterministic.
PointCloud makeSphere(std::size_t count) {
    std::vector<std::string> warnings;
    PointCloudBuilder builder({.normal = true}, count);
    const double goldenAngle = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (std::size_t i = 0; i < count; ++i) {
        const double z = 1.0 - (2.0 * static_cast<double>(i) + 1.0) / static_cast<double>(count);
        const double radius = std::sqrt(1.0 - z * z);
        const double angle = goldenAngle * static_cast<double>(i);
        PointRecord record;
        record.position = {radius * std::cos(angle), radius * std::sin(angle), z};
        record.normal = glm::vec3(record.position);
        builder.add(record);
    }
    return builder.finish(warnings);
}

}  // namespace

PointCloud makeSyntheticScene(std::string_view spec) {
    const std::size_t query = spec.find('?');
    const std::string_view name = spec.substr(0, query);
    std::size_t points = 4000;
    if (query != std::string_view::npos) {
        const std::string_view parameter = spec.substr(query + 1);
        constexpr std::string_view kPoints = "points=";
        if (!parameter.starts_with(kPoints)) {
            throw Error(fmt::format("unknown synthetic scene parameter '{}' (expected points=N)",
                                    parameter));
        }
        const std::string_view value = parameter.substr(kPoints.size());
        const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), points);
        if (ec != std::errc() || end != value.data() + value.size() || points == 0 ||
            points > 100'000'000) {
            throw Error(
                fmt::format("points={} is not a point count between 1 and 100000000", value));
        }
    }
    if (name == "sphere") {
        return makeSphere(points);
    }
    throw Error(fmt::format("there is no built-in scene '{}' (available: sphere)", name));
}

}  // namespace subscan
