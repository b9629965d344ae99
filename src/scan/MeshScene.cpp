#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/Error.h"
#include "core/Srgb.h"
#include "scan/Marble.h"
#include "scan/Scene.h"

namespace subscan {

namespace {

constexpr glm::vec3 kPlainGrey{0.7f, 0.7f, 0.7f};

/// Binned SAH: 16 bins per split find nearly the best plane at a fraction of the cost of
/// sorting (Wald 2007).
constexpr int kBinCount = 16;
constexpr std::uint32_t kMaxLeafTriangles = 4;
/// Below this depth splits follow the surface area heuristic; deeper ones split at the median,
/// which bounds the depth (and the traversal stack) even for pathological meshes.
constexpr int kMaxHeuristicDepth = 64;
constexpr std::size_t kTraversalStackSize = 128;

double surfaceArea(const Bounds& box) {
    if (box.empty()) {
        return 0.0;
    }
    const glm::dvec3 e = box.extent();
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

void addBounds(Bounds& into, const Bounds& other) {
    if (!other.empty()) {
        into.add(other.min);
        into.add(other.max);
    }
}

/// Squared distance from p to the box (0 inside).
double squaredDistanceToBox(const glm::dvec3& p, const Bounds& box) {
    const glm::dvec3 outside = glm::max(glm::max(box.min - p, p - box.max), 0.0);
    return glm::dot(outside, outside);
}

glm::dvec3 closestPointOnSegment(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec3 ab = b - a;
    const double length2 = glm::dot(ab, ab);
    const double t = length2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / length2, 0.0, 1.0) : 0.0;
    return a + t * ab;
}

/// The point of triangle abc nearest to p, by Voronoi regions (Ericson, Real-Time Collision
/// Detection, 5.1.5); degenerate triangles fall back to their edges.
glm::dvec3 closestPointOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                                  const glm::dvec3& c) {
    const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        return a;
    }
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        return b;
    }
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 && d1 - d3 > 0.0) {
        return a + (d1 / (d1 - d3)) * ab;
    }
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        return c;
    }
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 && d2 - d6 > 0.0) {
        return a + (d2 / (d2 - d6)) * ac;
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 && (d4 - d3) + (d5 - d6) > 0.0) {
        return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    }
    const double sum = va + vb + vc;
    if (!(sum > 0.0)) {
        const glm::dvec3 candidates[] = {closestPointOnSegment(p, a, b),
                                         closestPointOnSegment(p, b, c),
                                         closestPointOnSegment(p, c, a)};
        return *std::min_element(std::begin(candidates), std::end(candidates),
                                 [&](const glm::dvec3& x, const glm::dvec3& y) {
                                     return glm::dot(x - p, x - p) < glm::dot(y - p, y - p);
                                 });
    }
    return a + ab * (vb / sum) + ac * (vc / sum);
}

/// A triangle mesh in a bounding volume hierarchy.
class MeshScene final : public Scene {
  public:
    MeshScene(const PointCloud& mesh, AlbedoSource albedo);

    std::optional<SurfaceHit> intersect(const Ray& ray, double maxDistance) const override;
    Bounds bounds() const override { return bounds_; }
    double surfaceDistance(const glm::dvec3& p) const override;

  private:
    /// Interior nodes: the left child follows the node, `rightOrFirst` is the right child.
    /// Leaves (`count` > 0): triangles [rightOrFirst, rightOrFirst + count).
    struct Node {
        Bounds box;
        std::uint32_t rightOrFirst = 0;
        std::uint32_t count = 0;
    };
    /// Möller–Trumbore wants a corner and two edges.
    struct TriangleGeometry {
        glm::dvec3 corner, edge1, edge2;
    };

    std::uint32_t build(std::vector<std::uint32_t>& order, const std::vector<Bounds>& boxes,
                        const std::vector<glm::dvec3>& centroids, std::uint32_t begin,
                        std::uint32_t end, int depth);

    std::vector<glm::dvec3> vertices_;
    std::vector<glm::dvec3> vertexNormals_;
    std::vector<glm::vec3> vertexAlbedo_;  // linear; empty unless the mesh has colours
    std::vector<Triangle> triangles_;      // in BVH leaf order
    std::vector<TriangleGeometry> geometry_;
    std::vector<Node> nodes_;
    std::optional<MarbleAlbedo> marble_;
    Bounds bounds_;
};

MeshScene::MeshScene(const PointCloud& mesh, AlbedoSource albedo) {
    if (mesh.triangles.empty()) {
        throw Error("the mesh has no triangles (a PLY with a face element is needed)");
    }
    vertices_.resize(mesh.size());
    for (std::size_t i = 0; i < mesh.size(); ++i) {
        vertices_[i] = mesh.fileCoordinates(i);
    }
    for (const Triangle& triangle : mesh.triangles) {
        for (const std::uint32_t index : triangle) {
            if (index >= vertices_.size()) {
                throw Error(fmt::format("a mesh triangle refers to vertex {} of {}", index,
                                        vertices_.size()));
            }
        }
    }

    // Area-weighted vertex normals: the unnormalised face normal is twice the area.
    vertexNormals_.assign(vertices_.size(), glm::dvec3(0.0));
    std::vector<Bounds> boxes(mesh.triangles.size());
    std::vector<glm::dvec3> centroids(mesh.triangles.size());
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& triangle = mesh.triangles[t];
        const glm::dvec3& a = vertices_[triangle[0]];
        const glm::dvec3& b = vertices_[triangle[1]];
        const glm::dvec3& c = vertices_[triangle[2]];
        const glm::dvec3 weightedNormal = glm::cross(b - a, c - a);
        for (const std::uint32_t index : triangle) {
            vertexNormals_[index] += weightedNormal;
            boxes[t].add(vertices_[index]);
            bounds_.add(vertices_[index]);
        }
        centroids[t] = (a + b + c) / 3.0;
    }
    for (glm::dvec3& normal : vertexNormals_) {
        const double length = glm::length(normal);
        normal = length > 0.0 ? normal / length : glm::dvec3(0.0);
    }

    if (albedo == AlbedoSource::VertexColors && mesh.hasColors()) {
        vertexAlbedo_.reserve(mesh.size());
        for (const Rgba8& color : mesh.colors) {
            vertexAlbedo_.push_back(linearColor(color));
        }
    } else if (albedo == AlbedoSource::Marble) {
        marble_ = MarbleAlbedo::forBounds(bounds_);
    }

    std::vector<std::uint32_t> order(mesh.triangles.size());
    for (std::uint32_t i = 0; i < order.size(); ++i) {
        order[i] = i;
    }
    nodes_.reserve(2 * order.size() / kMaxLeafTriangles + 1);
    build(order, boxes, centroids, 0, static_cast<std::uint32_t>(order.size()), 0);

    triangles_.reserve(order.size());
    geometry_.reserve(order.size());
    for (const std::uint32_t index : order) {
        const Triangle& triangle = mesh.triangles[index];
        triangles_.push_back(triangle);
        const glm::dvec3& a = vertices_[triangle[0]];
        geometry_.push_back({a, vertices_[triangle[1]] - a, vertices_[triangle[2]] - a});
    }
}

std::uint32_t MeshScene::build(std::vector<std::uint32_t>& order, const std::vector<Bounds>& boxes,
                               const std::vector<glm::dvec3>& centroids, std::uint32_t begin,
                               std::uint32_t end, int depth) {
    const auto nodeIndex = static_cast<std::uint32_t>(nodes_.size());
    nodes_.emplace_back();
    Bounds box, centroidBox;
    for (std::uint32_t i = begin; i < end; ++i) {
        addBounds(box, boxes[order[i]]);
        centroidBox.add(centroids[order[i]]);
    }
    nodes_[nodeIndex].box = box;
    const std::uint32_t count = end - begin;
    const glm::dvec3 spread = centroidBox.extent();
    const int axis =
        spread.x >= spread.y && spread.x >= spread.z ? 0 : (spread.y >= spread.z ? 1 : 2);
    if (count <= kMaxLeafTriangles || !(spread[axis] > 0.0)) {
        nodes_[nodeIndex].rightOrFirst = begin;
        nodes_[nodeIndex].count = count;
        return nodeIndex;
    }

    auto* const first = order.data() + begin;
    auto* const last = order.data() + end;
    std::uint32_t* middle = nullptr;
    if (depth < kMaxHeuristicDepth) {
        auto binOf = [&](std::uint32_t triangle) {
            const double position =
                (centroids[triangle][axis] - centroidBox.min[axis]) / spread[axis];
            return std::min(kBinCount - 1, static_cast<int>(position * kBinCount));
        };
        std::array<Bounds, kBinCount> binBoxes{};
        std::array<std::uint32_t, kBinCount> binCounts{};
        for (std::uint32_t i = begin; i < end; ++i) {
            const int bin = binOf(order[i]);
            addBounds(binBoxes[bin], boxes[order[i]]);
            ++binCounts[bin];
        }
        // Cost of splitting after bin s: area-weighted triangle counts on both sides.
        std::array<double, kBinCount - 1> leftCost{};
        Bounds running;
        std::uint32_t runningCount = 0;
        for (int s = 0; s < kBinCount - 1; ++s) {
            addBounds(running, binBoxes[s]);
            runningCount += binCounts[s];
            leftCost[s] = surfaceArea(running) * runningCount;
        }
        running = Bounds{};
        runningCount = 0;
        double bestCost = std::numeric_limits<double>::infinity();
        int bestSplit = -1;
        for (int s = kBinCount - 1; s > 0; --s) {
            addBounds(running, binBoxes[s]);
            runningCount += binCounts[s];
            const double cost = leftCost[s - 1] + surfaceArea(running) * runningCount;
            if (cost < bestCost) {
                bestCost = cost;
                bestSplit = s;
            }
        }
        if (bestSplit > 0) {
            middle = std::partition(
                first, last, [&](std::uint32_t triangle) { return binOf(triangle) < bestSplit; });
        }
    }
    if (middle == nullptr || middle == first || middle == last) {
        middle = first + count / 2;
        std::nth_element(first, middle, last, [&](std::uint32_t a, std::uint32_t b) {
            return centroids[a][axis] < centroids[b][axis];
        });
    }
    const auto split = static_cast<std::uint32_t>(middle - order.data());
    build(order, boxes, centroids, begin, split, depth + 1);
    const std::uint32_t right = build(order, boxes, centroids, split, end, depth + 1);
    nodes_[nodeIndex].rightOrFirst = right;
    return nodeIndex;
}

std::optional<SurfaceHit> MeshScene::intersect(const Ray& ray, double maxDistance) const {
    // A huge finite reciprocal instead of infinity keeps 0 * (1 / 0) from making NaNs for rays
    // parallel to a slab that start on its plane.
    glm::dvec3 inverse;
    for (int axis = 0; axis < 3; ++axis) {
        inverse[axis] = ray.direction[axis] != 0.0 ? 1.0 / ray.direction[axis] : 1e300;
    }
    auto enterBox = [&](const Bounds& box, double limit) {
        const glm::dvec3 t1 = (box.min - ray.origin) * inverse;
        const glm::dvec3 t2 = (box.max - ray.origin) * inverse;
        const glm::dvec3 near = glm::min(t1, t2), far = glm::max(t1, t2);
        const double enter = std::max(std::max(near.x, near.y), std::max(near.z, 0.0));
        const double leave = std::min(std::min(far.x, far.y), std::min(far.z, limit));
        return enter <= leave ? enter : std::numeric_limits<double>::infinity();
    };

    double best = maxDistance;
    std::uint32_t bestTriangle = kInvalidIndex;
    double bestU = 0.0, bestV = 0.0;
    std::array<std::uint32_t, kTraversalStackSize> stack{};
    std::size_t stackSize = 0;
    if (enterBox(nodes_[0].box, best) < std::numeric_limits<double>::infinity()) {
        stack[stackSize++] = 0;
    }
    while (stackSize > 0) {
        const Node& node = nodes_[stack[--stackSize]];
        if (node.count > 0) {
            for (std::uint32_t t = node.rightOrFirst; t < node.rightOrFirst + node.count; ++t) {
                // Möller–Trumbore, two-sided, in double.
                const TriangleGeometry& g = geometry_[t];
                const glm::dvec3 p = glm::cross(ray.direction, g.edge2);
                const double determinant = glm::dot(g.edge1, p);
                if (determinant == 0.0) {
                    continue;  // parallel to the plane, or a degenerate triangle
                }
                const double inverseDeterminant = 1.0 / determinant;
                const glm::dvec3 s = ray.origin - g.corner;
                const double u = glm::dot(s, p) * inverseDeterminant;
                if (u < 0.0 || u > 1.0) {
                    continue;
                }
                const glm::dvec3 q = glm::cross(s, g.edge1);
                const double v = glm::dot(ray.direction, q) * inverseDeterminant;
                if (v < 0.0 || u + v > 1.0) {
                    continue;
                }
                const double distance = glm::dot(g.edge2, q) * inverseDeterminant;
                if (distance >= 0.0 && distance < best) {
                    best = distance;
                    bestTriangle = t;
                    bestU = u;
                    bestV = v;
                }
            }
            continue;
        }
        // Visit the nearer child first: its hits shorten `best` and prune the other.
        const std::uint32_t left = static_cast<std::uint32_t>(&node - nodes_.data()) + 1;
        const std::uint32_t right = node.rightOrFirst;
        const double enterLeft = enterBox(nodes_[left].box, best);
        const double enterRight = enterBox(nodes_[right].box, best);
        const bool leftFirst = enterLeft <= enterRight;
        const double enterNear = leftFirst ? enterLeft : enterRight;
        const double enterFar = leftFirst ? enterRight : enterLeft;
        if (enterFar < std::numeric_limits<double>::infinity()) {
            stack[stackSize++] = leftFirst ? right : left;
        }
        if (enterNear < std::numeric_limits<double>::infinity()) {
            stack[stackSize++] = leftFirst ? left : right;
        }
    }
    if (bestTriangle == kInvalidIndex) {
        return std::nullopt;
    }

    const Triangle& triangle = triangles_[bestTriangle];
    const TriangleGeometry& g = geometry_[bestTriangle];
    const double w = 1.0 - bestU - bestV;
    glm::dvec3 faceNormal = glm::normalize(glm::cross(g.edge1, g.edge2));
    glm::dvec3 normal = w * vertexNormals_[triangle[0]] + bestU * vertexNormals_[triangle[1]] +
                        bestV * vertexNormals_[triangle[2]];
    const double normalLength = glm::length(normal);
    normal = normalLength > 0.0 ? normal / normalLength : faceNormal;
    // Open meshes can be seen from behind (the inside of the bunny through its base): report the
    // side the ray sees, as a scanner would.
    if (glm::dot(faceNormal, ray.direction) > 0.0) {
        normal = -normal;
    }

    SurfaceHit hit;
    hit.distance = best;
    hit.normal = facingRay(normal, ray.direction);
    const glm::dvec3 point = ray.origin + best * ray.direction;
    if (!vertexAlbedo_.empty()) {
        hit.albedo = static_cast<float>(w) * vertexAlbedo_[triangle[0]] +
                     static_cast<float>(bestU) * vertexAlbedo_[triangle[1]] +
                     static_cast<float>(bestV) * vertexAlbedo_[triangle[2]];
    } else if (marble_) {
        hit.albedo = (*marble_)(point);
    } else {
        hit.albedo = kPlainGrey;
    }
    return hit;
}

double MeshScene::surfaceDistance(const glm::dvec3& p) const {
    double best = std::numeric_limits<double>::infinity();  // squared
    std::array<std::uint32_t, kTraversalStackSize> stack{};
    std::size_t stackSize = 0;
    stack[stackSize++] = 0;
    while (stackSize > 0) {
        const std::uint32_t index = stack[--stackSize];
        const Node& node = nodes_[index];
        if (squaredDistanceToBox(p, node.box) >= best) {
            continue;
        }
        if (node.count > 0) {
            for (std::uint32_t t = node.rightOrFirst; t < node.rightOrFirst + node.count; ++t) {
                const TriangleGeometry& g = geometry_[t];
                const glm::dvec3 closest =
                    closestPointOnTriangle(p, g.corner, g.corner + g.edge1, g.corner + g.edge2);
                best = std::min(best, glm::dot(closest - p, closest - p));
            }
            continue;
        }
        const std::uint32_t left = index + 1;
        const std::uint32_t right = node.rightOrFirst;
        const bool leftFirst =
            squaredDistanceToBox(p, nodes_[left].box) <= squaredDistanceToBox(p, nodes_[right].box);
        stack[stackSize++] = leftFirst ? right : left;
        stack[stackSize++] = leftFirst ? left : right;
    }
    return std::sqrt(best);
}

}  // namespace

std::unique_ptr<Scene> makeMeshScene(const PointCloud& mesh, AlbedoSource albedo) {
    return std::make_unique<MeshScene>(mesh, albedo);
}

}  // namespace subscan
