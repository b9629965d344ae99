#include "lod/NodeSelection.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>
#include <queue>
#include <thread>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "core/Error.h"
#include "core/Parallel.h"
#include "io/ScanLoader.h"

namespace subscan::lod {

namespace {

struct Sphere {
    glm::dvec3 centre;
    double radius = 0.0;
};

Sphere boundingSphere(const OctreeCube& cube, const laz::VoxelKey& key) {
    const double side = 2.0 * cube.halfSize / static_cast<double>(std::int64_t{1} << key.level);
    const glm::dvec3 min = cube.center - cube.halfSize + glm::dvec3(key.x, key.y, key.z) * side;
    return {min + 0.5 * side, 0.5 * std::sqrt(3.0) * side};
}

/// The six planes of the camera's view volume in file coordinates (Gribb and Hartmann: rows of
/// projection * view), each scaled to a unit normal pointing inwards.
std::array<glm::dvec4, 6> viewPlanes(const Camera& camera) {
    const glm::dmat4 clip = camera.projection() * camera.view;
    const glm::dmat4 rows = glm::transpose(clip);
    std::array<glm::dvec4, 6> planes{rows[3] + rows[0], rows[3] - rows[0], rows[3] + rows[1],
                                     rows[3] - rows[1], rows[3] + rows[2], rows[3] - rows[2]};
    for (glm::dvec4& plane : planes) {
        plane /= glm::length(glm::dvec3(plane));
    }
    return planes;
}

bool inView(const std::array<glm::dvec4, 6>& planes, const Sphere& sphere) {
    return std::all_of(planes.begin(), planes.end(), [&](const glm::dvec4& plane) {
        return glm::dot(glm::dvec3(plane), sphere.centre) + plane.w >= -sphere.radius;
    });
}

/// The nearest distance from the eye to the sphere along the view, at least the near plane's.
double nearestDistance(const Camera& camera, const Sphere& sphere) {
    if (camera.orthographic()) {
        return 1.0;  // pixels per unit do not change with distance
    }
    return std::max(glm::length(sphere.centre - camera.eye()) - sphere.radius, camera.nearPlane);
}

/// Pixels per scene unit at `distance`.
double pixelsPerUnit(const Camera& camera, double distance) {
    return camera.focalLengthPixels() / distance;
}

}  // namespace

std::vector<std::size_t> selectNodes(const NodeSource& source, const Camera& camera,
                                     std::uint64_t pointBudget) {
    return selectNodes(source, std::span(&camera, 1), pointBudget);
}

std::vector<std::size_t> selectNodes(const NodeSource& source, std::span<const Camera> cameras,
                                     std::uint64_t pointBudget) {
    const OctreeCube& cube = source.info().cube;
    const std::span<const StreamedNode> nodes = source.nodes();
    std::vector<std::array<glm::dvec4, 6>> planes;
    for (const Camera& camera : cameras) {
        planes.push_back(viewPlanes(camera));
    }
    struct Candidate {
        double pixels;
        std::size_t index;
        bool operator<(const Candidate& other) const {
            // Larger first; among equals the earlier node, so that the order is the same on
            // every run.
            return pixels != other.pixels ? pixels < other.pixels : index > other.index;
        }
    };
    // A node's size is the largest any view shows it at.
    const auto candidate = [&](std::size_t index) -> std::optional<Candidate> {
        const Sphere sphere = boundingSphere(cube, nodes[index].key);
        std::optional<Candidate> largest;
        for (std::size_t view = 0; view < cameras.size(); ++view) {
            const Camera& camera = cameras[view];
            if (!inView(planes[view], sphere)) {
                continue;
            }
            const bool holdsEye = glm::length(sphere.centre - camera.eye()) <= sphere.radius;
            const double pixels =
                holdsEye ? std::numeric_limits<double>::infinity()
                         : sphere.radius * pixelsPerUnit(camera, nearestDistance(camera, sphere));
            if (!largest || pixels > largest->pixels) {
                largest = Candidate{pixels, index};
            }
        }
        return largest;
    };

    std::vector<std::size_t> selected{0};  // the root, whatever the budget
    std::uint64_t points = nodes[0].pointCount;
    std::priority_queue<Candidate> queue;
    const auto offerChildren = [&](std::size_t parent) {
        const laz::VoxelKey& key = nodes[parent].key;
        const double spacing = cube.rootSpacing / static_cast<double>(std::int64_t{1} << key.level);
        for (int octant = 0; octant < 8; ++octant) {
            const laz::VoxelKey child{key.level + 1, 2 * key.x + (octant & 1),
                                      2 * key.y + ((octant >> 1) & 1),
                                      2 * key.z + ((octant >> 2) & 1)};
            const std::size_t index = source.find(child);
            if (index == nodes.size()) {
                continue;
            }
            const Sphere sphere = boundingSphere(cube, child);
            if (std::none_of(cameras.begin(), cameras.end(), [&](const Camera& camera) {
                    return spacing * pixelsPerUnit(camera, nearestDistance(camera, sphere)) >=
                           kFinestParentSpacingPixels;
                })) {
                continue;
            }
            if (const std::optional<Candidate> next = candidate(index)) {
                queue.push(*next);
            }
        }
    };
    offerChildren(0);
    while (!queue.empty()) {
        const Candidate next = queue.top();
        queue.pop();
        if (points + nodes[next.index].pointCount > pointBudget) {
            break;
        }
        points += nodes[next.index].pointCount;
        selected.push_back(next.index);
        offerChildren(next.index);
    }
    return selected;
}

std::vector<std::size_t> topLevels(const NodeSource& source, std::uint64_t points) {
    const std::span<const StreamedNode> nodes = source.nodes();
    std::vector<std::size_t> chosen;
    std::uint64_t taken = 0;
    // nodes() is ordered by level: each level is taken whole or not at all.
    for (std::size_t begin = 0; begin < nodes.size();) {
        std::size_t end = begin;
        std::uint64_t levelPoints = 0;
        while (end < nodes.size() && nodes[end].key.level == nodes[begin].key.level) {
            levelPoints += nodes[end++].pointCount;
        }
        if (begin > 0 && taken + levelPoints > points) {
            break;
        }
        for (std::size_t i = begin; i < end; ++i) {
            chosen.push_back(i);
        }
        taken += levelPoints;
        begin = end;
    }
    return chosen;
}

PointCloud loadNodes(const NodeSource& source, std::span<const std::size_t> nodes,
                     std::vector<std::string>& warnings, unsigned threads,
                     const std::function<bool()>& cancelled, std::vector<std::size_t>* read) {
    std::vector<std::optional<PointCloud>> loaded(nodes.size());
    std::vector<std::string> failures(nodes.size());
    std::atomic<std::size_t> next{0};
    const auto work = [&] {
        for (std::size_t i = next++; i < nodes.size(); i = next++) {
            if (cancelled && cancelled()) {
                return;
            }
            try {
                loaded[i] = source.load(nodes[i]);
            } catch (const Error& error) {
                failures[i] = fmt::format("{}; it is left out", error.what());
            } catch (const std::bad_alloc&) {
                failures[i] = fmt::format("{}: out of memory; it is left out",
                                          nodeName(source.nodes()[nodes[i]].key));
            }
        }
    };
    {
        const unsigned count =
            std::clamp<unsigned>(threads != 0 ? threads : std::thread::hardware_concurrency(), 1,
                                 static_cast<unsigned>(std::max<std::size_t>(nodes.size(), 1)));
        std::vector<std::jthread> workers;
        for (unsigned t = 1; t < count; ++t) {
            workers.emplace_back(work);
        }
        work();
    }

    PointCloud cloud;
    cloud.origin =
        source.info().bounds.empty() ? source.info().cube.center : source.info().bounds.center();
    std::size_t total = 0;
    bool colors = true, normals = true, intensities = true, classifications = true;
    bool any = false;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        if (!failures[i].empty()) {
            warnings.push_back(failures[i]);
        }
        if (loaded[i]) {
            if (read != nullptr) {
                read->push_back(nodes[i]);
            }
            total += loaded[i]->size();
            colors = colors && loaded[i]->hasColors();
            normals = normals && loaded[i]->hasNormals();
            intensities = intensities && loaded[i]->hasIntensities();
            classifications = classifications && loaded[i]->hasClassifications();
            any = true;
        }
    }
    if (!any) {
        colors = normals = intensities = classifications = false;
    }
    cloud.positions.reserve(total);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        if (!loaded[i]) {
            continue;
        }
        PointCloud& part = *loaded[i];
        const glm::dvec3 shift = part.origin - cloud.origin;
        for (const glm::vec3& p : part.positions) {
            cloud.positions.emplace_back(glm::dvec3(p) + shift);
        }
        if (!part.bounds.empty()) {
            cloud.bounds.add(part.bounds.min);
            cloud.bounds.add(part.bounds.max);
        }
        const auto append = [](auto& to, auto& from, bool keep) {
            if (keep) {
                to.insert(to.end(), from.begin(), from.end());
            }
        };
        append(cloud.colors, part.colors, colors);
        cloud.colorCutTo8Bits = cloud.colorCutTo8Bits || (colors && part.colorCutTo8Bits);
        // A dataset's tiles share its grid; of several, the finest is the one to keep.
        if (part.coordinateStep > 0.0) {
            cloud.coordinateStep = cloud.coordinateStep > 0.0
                                       ? std::min(cloud.coordinateStep, part.coordinateStep)
                                       : part.coordinateStep;
        }
        append(cloud.normals, part.normals, normals);
        append(cloud.intensities, part.intensities, intensities);
        append(cloud.classifications, part.classifications, classifications);
        part = PointCloud{};
    }
    // As a whole file's: a COPC file indexed from one with zeros holds them too.
    ignoreZeroNormals(cloud, warnings);
    return cloud;
}

namespace {

/// A part of the survey next to a loaded node where the view loaded only coarser levels: the
/// neighbouring cube on the node's level, and the spacing there.
struct CoarserBeside {
    glm::dvec3 min{0.0}, max{0.0};
    double spacing = 0.0;
};

/// LoadedScan::levelSpacing of `cloud`, loaded from `nodes`. The view takes nodes from the root
/// down (a parent before its children), so the finest node it loaded around a point is found
/// by going down from the root while the child that holds the point is one of them; its level
/// gives the spacing. Where a part of the view with a coarser spacing lies within that spacing
/// of the point, that spacing: the gap between the finer points' last row and the coarser
/// ones' first is the coarser spacing, which the finer points beside the border must bridge.
/// Only where the view left out the next level down does the level's spacing hold: where the
/// survey holds nothing deeper (a node holding every point of its cube, as the indexer leaves
/// a cube of few points), the points lie at the scan's own spacing, which their estimate
/// gives, so they get 0 (none) unless a coarser part lies beside them; at a budget that takes
/// every point, every point. `nodes`: those read; a node that could not be read counts as left
/// out, so its ancestors' points in its cube take their own level's spacing, as where the view
/// cut the octree there.
std::vector<float> levelSpacingOf(const NodeSource& source, std::span<const std::size_t> nodes,
                                  const PointCloud& cloud) {
    const std::span<const StreamedNode> all = source.nodes();
    std::vector<bool> loaded(all.size(), false);
    for (const std::size_t node : nodes) {
        loaded[node] = true;
    }
    const OctreeCube& cube = source.info().cube;
    const glm::dvec3 corner = cube.center - cube.halfSize;
    const auto isLoaded = [&](const laz::VoxelKey& key) {
        const std::size_t node = source.find(key);
        return node < all.size() && loaded[node];
    };
    // Per loaded node, its neighbours on its level that hold points the view did not load,
    // with the spacing of their finest loaded ancestor.
    std::vector<std::vector<CoarserBeside>> coarser(all.size());
    for (const std::size_t node : nodes) {
        const laz::VoxelKey& key = all[node].key;
        const std::int32_t cells = std::int32_t{1} << key.level;
        const double side = 2.0 * cube.halfSize / cells;
        for (int dz = -1; dz <= 1; ++dz) {
            for (int dy = -1; dy <= 1; ++dy) {
                for (int dx = -1; dx <= 1; ++dx) {
                    const laz::VoxelKey beside{key.level, key.x + dx, key.y + dy, key.z + dz};
                    if (beside.x < 0 || beside.y < 0 || beside.z < 0 || beside.x >= cells ||
                        beside.y >= cells || beside.z >= cells ||
                        source.find(beside) >= all.size() || isLoaded(beside)) {
                        continue;  // outside the octree, empty, or as fine
                    }
                    int level = key.level - 1;
                    while (level > 0 && !isLoaded({level, beside.x >> (key.level - level),
                                                   beside.y >> (key.level - level),
                                                   beside.z >> (key.level - level)})) {
                        --level;
                    }
                    const glm::dvec3 min = corner + side * glm::dvec3(beside.x, beside.y, beside.z);
                    coarser[node].push_back(
                        {min, min + side, std::ldexp(cube.rootSpacing, -level)});
                }
            }
        }
    }
    std::vector<float> spacing(cloud.size());
    inParallel(cloud.size(), [&](std::size_t i) {
        const glm::dvec3 position = cloud.fileCoordinates(i);
        std::size_t finest = source.find(nodeKeyAt(cube, position, 0));
        bool cut = false;  // the view left out the next level down here
        for (int level = 1;; ++level) {
            const std::size_t child = source.find(nodeKeyAt(cube, position, level));
            if (child >= all.size() || !loaded[child]) {
                cut = child < all.size();
                break;
            }
            finest = child;
        }
        double own = 0.0;
        if (finest < all.size()) {
            own = cut ? std::ldexp(cube.rootSpacing, -all[finest].key.level) : 0.0;
            for (const CoarserBeside& part : coarser[finest]) {
                const glm::dvec3 outside =
                    glm::max(glm::max(part.min - position, position - part.max), 0.0);
                if (part.spacing > own && glm::length(outside) <= part.spacing) {
                    own = part.spacing;
                }
            }
        }
        spacing[i] = static_cast<float>(own);
    });
    return spacing;
}

}  // namespace

LoadedScan loadStreamedScan(const NodeSource& source, std::span<const std::size_t> nodes,
                            bool withSourceWarnings, const std::function<bool()>& cancelled) {
    const auto start = std::chrono::steady_clock::now();
    LoadedScan scan;
    if (withSourceWarnings) {
        scan.warnings = source.info().warnings;
    }
    std::vector<std::size_t> read;
    scan.cloud = loadNodes(source, nodes, scan.warnings, 0, cancelled, &read);
    if (scan.cloud.size() == 0 && !nodes.empty() && !(cancelled && cancelled())) {
        throw Error(fmt::format("{}: none of the {} nodes it needs could be read ({})",
                                source.info().name, nodes.size(),
                                scan.warnings.empty() ? "?" : scan.warnings.back()));
    }
    scan.levelSpacing = levelSpacingOf(source, read, scan.cloud);
    scan.cloud.bounds.add(source.info().bounds.min);
    scan.cloud.bounds.add(source.info().bounds.max);
    scan.format = source.info().format;
    scan.formatDetail = source.info().formatDetail;
    scan.loadMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return scan;
}

LoadedScan loadStreamedOverview(const NodeSource& source, std::vector<std::size_t>* nodes) {
    for (std::uint64_t points = kOverviewPoints;; points *= 8) {
        std::vector<std::size_t> chosen = topLevels(source, points);
        try {
            LoadedScan scan = loadStreamedScan(source, chosen);
            if (nodes != nullptr) {
                *nodes = std::move(chosen);
            }
            return scan;
        } catch (const Error&) {
            if (chosen.size() == source.nodes().size()) {
                throw;
            }
        }
    }
}

}  // namespace subscan::lod
