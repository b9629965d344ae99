#include "scan/VirtualScanner.h"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <exception>
#include <mutex>
#include <numbers>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/Srgb.h"
#include "scan/Marble.h"

namespace subscan {

namespace {

/// Scanner distance from the bounding sphere's centre, in bounding-sphere radii.
constexpr double kDistanceInRadii = 3.0;
constexpr double kRingElevationDegrees = 25.0;
constexpr int kFewestViewsWithTopView = 5;

/// SplitMix64 (Steele et al. 2014): a fast, well-mixed hash of a 64-bit value.
std::uint64_t splitMix64(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

/// A standard normal draw that depends only on (seed, view, pixel): Box–Muller on two hashes.
double gaussianForRay(std::uint64_t seed, std::uint64_t view, std::uint64_t pixel) {
    const std::uint64_t first = splitMix64(splitMix64(splitMix64(seed) ^ view) ^ pixel);
    const std::uint64_t second = splitMix64(first);
    constexpr double kUnit = 1.0 / 9007199254740992.0;                   // 2^-53
    const double u1 = (static_cast<double>(first >> 11) + 1.0) * kUnit;  // (0, 1]: log is finite
    const double u2 = static_cast<double>(second >> 11) * kUnit;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

double boundingRadius(const Bounds& bounds) {
    const double radius = 0.5 * glm::length(bounds.extent());
    // A scene of one point still needs a camera that can see it.
    return radius > 0.0 ? radius : 1e-3;
}

/// The hits of one image row of one view.
using RowPoints = std::vector<PointRecord>;

struct ScanRows {
    std::vector<RowPoints> rows;  // view-major, then row
    std::size_t pointCount = 0;
};

/// Casts every ray of every view; rows are handed to threads one at a time and each ray's noise
/// is seeded by its own index, so neither the split nor the thread count changes the result.
ScanRows castRays(const Scene& scene, const ScannerSettings& settings, unsigned threads) {
    validate(settings);
    const Bounds bounds = scene.bounds();
    const std::vector<ScannerView> views = scannerViews(bounds, settings.views);
    const double sigma = noiseSigma(bounds, settings);
    const double maxDistance = (kDistanceInRadii + 1.0) * boundingRadius(bounds);
    const MarbleAlbedo marble = MarbleAlbedo::forBounds(bounds);
    const auto resolution = static_cast<std::size_t>(settings.resolution);

    ScanRows result;
    result.rows.resize(views.size() * resolution);
    auto scanRow = [&](std::size_t job) {
        const std::size_t viewIndex = job / resolution;
        const std::size_t row = job % resolution;
        const ScannerView& view = views[viewIndex];
        const double y =
            (1.0 - 2.0 * (static_cast<double>(row) + 0.5) / static_cast<double>(resolution)) *
            view.tanHalfFov;
        RowPoints& points = result.rows[job];
        for (std::size_t column = 0; column < resolution; ++column) {
            const double x =
                (2.0 * (static_cast<double>(column) + 0.5) / static_cast<double>(resolution) -
                 1.0) *
                view.tanHalfFov;
            const Ray ray{view.position,
                          glm::normalize(view.forward + x * view.right + y * view.up)};
            const std::optional<SurfaceHit> hit = scene.intersect(ray, maxDistance);
            if (!hit) {
                continue;
            }
            const glm::dvec3 onSurface = ray.origin + hit->distance * ray.direction;
            PointRecord point;
            point.position = onSurface;
            if (sigma > 0.0) {
                const double offset =
                    sigma * gaussianForRay(settings.seed, viewIndex, row * resolution + column);
                point.position = ray.origin + (hit->distance + offset) * ray.direction;
            }
            if (settings.color == ScannerSettings::Color::Scene) {
                point.color = srgb8Color(hit->albedo);
            } else if (settings.color == ScannerSettings::Color::Marble) {
                point.color = srgb8Color(marble(onSurface));
            }
            point.normal = glm::vec3(hit->normal);
            points.push_back(point);
        }
    };

    const std::size_t jobs = result.rows.size();
    unsigned workers = threads != 0 ? threads : std::thread::hardware_concurrency();
    workers = static_cast<unsigned>(std::clamp<std::size_t>(workers, 1, jobs));
    std::atomic<std::size_t> nextJob{0};
    std::atomic<bool> failed{false};
    std::exception_ptr failure;
    std::mutex failureMutex;
    auto work = [&] {
        try {
            for (std::size_t job = nextJob++; job < jobs && !failed; job = nextJob++) {
                scanRow(job);
            }
        } catch (...) {
            const std::lock_guard lock(failureMutex);
            if (!failure) {
                failure = std::current_exception();
            }
            failed = true;
        }
    };
    {
        std::vector<std::jthread> pool;
        for (unsigned i = 1; i < workers; ++i) {
            pool.emplace_back(work);
        }
        work();
    }
    if (failure) {
        std::rethrow_exception(failure);
    }
    for (const RowPoints& points : result.rows) {
        result.pointCount += points.size();
    }
    if (result.pointCount == 0) {
        throw Error(
            fmt::format("the virtual scanner hit nothing: no ray of its {} views met "
                        "the scene",
                        settings.views));
    }
    return result;
}

/// Builds the cloud from the rows, keeping `keep` of the `total` points evenly spread through
/// the scan's order: point floor(k * total / keep) for k = 0..keep-1 (all when keep == total),
/// stepped exactly in integers without forming k * total. Positions are rounded to float once,
/// relative to the centre of the exact bounds (PointCloudBuilder would round twice: relative to
/// the first point, then to the centre). Rows are freed as they are copied.
PointCloud buildCloud(ScanRows scan, const ScannerSettings& settings, std::size_t keep) {
    const std::size_t total = scan.pointCount;
    if (total > kMaxPoints) {
        throw Error(fmt::format("the scan has {} points, more than the {} subscan can hold", total,
                                kMaxPoints));
    }
    auto forEachKept = [&](bool release, auto&& visit) {
        const std::size_t step = total / keep, extra = total % keep;
        std::size_t index = 0, remainder = 0, kept = 0, rowStart = 0;
        for (RowPoints& points : scan.rows) {
            const std::size_t rowEnd = rowStart + points.size();
            for (; kept < keep && index < rowEnd; ++kept) {
                visit(points[index - rowStart]);
                index += step;
                remainder += extra;
                if (remainder >= keep) {
                    ++index;
                    remainder -= keep;
                }
            }
            rowStart = rowEnd;
            if (release) {
                RowPoints().swap(points);
            }
        }
    };
    PointCloud cloud;
    forEachKept(false, [&](const PointRecord& point) { cloud.bounds.add(point.position); });
    cloud.origin = cloud.bounds.center();
    const bool colors = settings.color != ScannerSettings::Color::None;
    cloud.positions.reserve(keep);
    cloud.colors.reserve(colors ? keep : 0);
    cloud.normals.reserve(settings.normals ? keep : 0);
    forEachKept(true, [&](const PointRecord& point) {
        cloud.positions.emplace_back(point.position - cloud.origin);
        if (colors) {
            cloud.colors.push_back(point.color);
        }
        if (settings.normals) {
            cloud.normals.push_back(point.normal);
        }
    });
    return cloud;
}

}  // namespace

void validate(const ScannerSettings& settings) {
    if (settings.views < 1 || settings.views > kMaxScannerViews) {
        throw Error(fmt::format("the scanner needs 1 to {} views, not {}", kMaxScannerViews,
                                settings.views));
    }
    if (settings.resolution < 1 || settings.resolution > kMaxScannerResolution) {
        throw Error(fmt::format("the scanner resolution must be 1 to {}, not {}",
                                kMaxScannerResolution, settings.resolution));
    }
    if (!(std::isfinite(settings.noise) && settings.noise >= 0.0)) {
        throw Error(fmt::format("the scanner noise must be a finite distance >= 0, not {}",
                                settings.noise));
    }
    if (settings.color != ScannerSettings::Color::None &&
        settings.color != ScannerSettings::Color::Scene &&
        settings.color != ScannerSettings::Color::Marble) {
        throw Error("the scanner colour mode is not none, scene or marble");
    }
}

void to_json(nlohmann::json& json, const ScannerSettings& settings) {
    json = {{"views", settings.views},
            {"resolution", settings.resolution},
            {"noise", settings.noise},
            {"noise_in_spacing_units", settings.noiseInSpacingUnits},
            {"color", colorModeName(settings.color)},
            {"normals", settings.normals},
            {"seed", settings.seed}};
}

void from_json(const nlohmann::json& json, ScannerSettings& settings) {
    if (!json.is_object()) {
        throw Error("scanner settings must be a JSON object");
    }
    ScannerSettings read;
    for (const auto& [key, value] : json.items()) {
        try {
            if (key == "views") {
                read.views = value.get<int>();
            } else if (key == "resolution") {
                read.resolution = value.get<int>();
            } else if (key == "noise") {
                read.noise = value.get<double>();
            } else if (key == "noise_in_spacing_units") {
                read.noiseInSpacingUnits = value.get<bool>();
            } else if (key == "color") {
                const auto name = value.get<std::string>();
                const auto color = parseColorMode(name);
                if (!color) {
                    throw Error(
                        fmt::format("the scanner setting 'color' is '{}', not none, "
                                    "scene or marble",
                                    name));
                }
                read.color = *color;
            } else if (key == "normals") {
                read.normals = value.get<bool>();
            } else if (key == "seed") {
                read.seed = value.get<std::uint64_t>();
            } else {
                throw Error(fmt::format("'{}' is not a scanner setting", key));
            }
        } catch (const nlohmann::json::exception&) {
            throw Error(fmt::format("the scanner setting '{}' has the wrong type ({})", key,
                                    value.type_name()));
        }
    }
    validate(read);
    settings = read;
}

std::optional<ScannerSettings::Color> parseColorMode(std::string_view name) {
    for (const auto color : {ScannerSettings::Color::None, ScannerSettings::Color::Scene,
                             ScannerSettings::Color::Marble}) {
        if (name == colorModeName(color)) {
            return color;
        }
    }
    return std::nullopt;
}

std::string_view colorModeName(ScannerSettings::Color color) {
    switch (color) {
        case ScannerSettings::Color::None:
            return "none";
        case ScannerSettings::Color::Scene:
            return "scene";
        case ScannerSettings::Color::Marble:
            return "marble";
    }
    return "unknown";
}

std::optional<NoiseAmount> parseNoiseAmount(std::string_view text) {
    NoiseAmount amount;
    if (!text.empty() && text.back() == 'h') {
        amount.inSpacingUnits = true;
        text.remove_suffix(1);
    }
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), amount.value);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size() ||
        !std::isfinite(amount.value) || amount.value < 0.0) {
        return std::nullopt;
    }
    return amount;
}

std::vector<ScannerView> scannerViews(const Bounds& bounds, int views) {
    const glm::dvec3 centre = bounds.empty() ? glm::dvec3(0.0) : bounds.center();
    const double radius = boundingRadius(bounds);
    const double distance = kDistanceInRadii * radius;
    // The square image's inscribed circle is the bounding sphere's silhouette.
    const double tanHalfFov = radius / std::sqrt(distance * distance - radius * radius);

    const bool topView = views >= kFewestViewsWithTopView;
    const int ringViews = topView ? views - 1 : views;
    const double elevation = kRingElevationDegrees * std::numbers::pi / 180.0;
    std::vector<ScannerView> result;
    result.reserve(static_cast<std::size_t>(std::max(views, 0)));
    for (int k = 0; k < ringViews; ++k) {
        const double azimuth = 2.0 * std::numbers::pi * k / ringViews;
        const double tilt = k % 2 == 0 ? elevation : -elevation;
        const glm::dvec3 outward(std::sin(azimuth) * std::cos(tilt), std::sin(tilt),
                                 std::cos(azimuth) * std::cos(tilt));
        ScannerView view;
        view.position = centre + distance * outward;
        view.forward = -outward;
        view.right = glm::normalize(glm::cross(view.forward, glm::dvec3(0.0, 1.0, 0.0)));
        view.up = glm::cross(view.right, view.forward);
        view.tanHalfFov = tanHalfFov;
        result.push_back(view);
    }
    if (topView) {
        ScannerView view;
        view.position = centre + glm::dvec3(0.0, distance, 0.0);
        view.forward = {0.0, -1.0, 0.0};
        view.up = {0.0, 0.0, -1.0};  // the image's top is the back of the scene
        view.right = glm::cross(view.forward, view.up);
        view.tanHalfFov = tanHalfFov;
        result.push_back(view);
    }
    return result;
}

double scanSpacing(const Bounds& bounds, const ScannerSettings& settings) {
    const double radius = boundingRadius(bounds);
    const double distance = kDistanceInRadii * radius;
    const double tanHalfFov = radius / std::sqrt(distance * distance - radius * radius);
    return distance * 2.0 * tanHalfFov / std::max(settings.resolution, 1);
}

double noiseSigma(const Bounds& bounds, const ScannerSettings& settings) {
    return settings.noiseInSpacingUnits ? settings.noise * scanSpacing(bounds, settings)
                                        : settings.noise;
}

PointCloud scanScene(const Scene& scene, const ScannerSettings& settings, unsigned threads) {
    ScanRows scan = castRays(scene, settings, threads);
    const std::size_t total = scan.pointCount;
    return buildCloud(std::move(scan), settings, total);
}

PointCloud scanToPointCount(const Scene& scene, ScannerSettings settings, std::size_t count,
                            unsigned threads) {
    if (count == 0 || count > kMaxPoints) {
        throw Error(fmt::format("a scan cannot have {} points", count));
    }
    // A coarse probe measures how much of the image the scene covers; hits grow with the square
    // of the resolution, so the probe predicts the resolution, and misses enlarge it.
    constexpr int kProbeResolution = 16;
    constexpr double kMargin = 1.02;
    settings.resolution = kProbeResolution;
    ScanRows scan = castRays(scene, settings, threads);
    bool probing = true;
    while (probing || scan.pointCount < count) {
        const double ratio =
            std::sqrt(static_cast<double>(count) / static_cast<double>(scan.pointCount));
        const double predicted = std::ceil(settings.resolution * ratio * kMargin);
        const int next =
            probing ? static_cast<int>(std::max(1.0, predicted))
                    : static_cast<int>(std::max<double>(settings.resolution + 1, predicted));
        if (next > kMaxScannerResolution) {
            throw Error(fmt::format("the virtual scanner cannot produce {} points with {} views",
                                    count, settings.views));
        }
        settings.resolution = next;
        scan = castRays(scene, settings, threads);
        probing = false;
    }
    return buildCloud(std::move(scan), settings, count);
}

}  // namespace subscan
