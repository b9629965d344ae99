#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "core/PointCloud.h"

namespace subscan {

/// The neighbourhood sizes (the point included) a normal is fitted to. Small ones follow a
/// scanner's noise and overlapping scans' offsets, large ones round off curved and thin parts:
/// each point takes the size its neighbours lie flattest in (the smallest surface variation of
/// Pauly et al. 2002), which is a large one on a noisy flat part and a small one on a curved
/// clean part. Measured through `eval` at 1024² (bench/README.md, "Normals that belong to the
/// points"): a fixed 16 gave 3.7 degrees mean on the bunny's vertices and 5.5 on its range
/// scans, these sizes 3.4 and 3.9; adding 64 gives 3.4 and 3.5 but costs a third more time
/// (the search for the largest is three quarters of it).
inline constexpr std::array<std::size_t, 5> kNormalNeighbourhoods = {12, 16, 24, 32, 48};

/// Per point, the unit normal of the plane through its nearest points in the least-squares
/// sense: the eigenvector of their covariance with the smallest eigenvalue (principal component
/// analysis, Hoppe et al. 1992), over the neighbourhood of kNormalNeighbourhoods they lie
/// flattest in. Where the neighbours determine no plane (fewer than 3 distinct points, or all
/// on one line) the normal is 0.
/// Oriented towards `sensor` (file coordinates) where one is known; else its sign is arbitrary
/// and the renderer faces it to the eye. Runs on every core.
/// `cancelled` (may be empty) is asked now and then, from any thread; once it says yes the
/// work stops and the result is incomplete.
std::vector<glm::vec3> estimateNormals(const PointCloud& cloud,
                                       const std::optional<glm::dvec3>& sensor = std::nullopt,
                                       const std::function<bool()>& cancelled = {});

/// Up to this many points a cloud without normals of its own gets them estimated when it is
/// loaded for rendering (about 3 s for 1.1 M points on two cores, bench/README.md); larger ones
/// keep the screen-space normals unless the settings ask for the points' (`surface.normals:
/// points`, which `render`, `turntable`, `bench` and `eval` honour whatever the size), so that
/// opening a survey does not wait minutes for them.
inline constexpr std::size_t kAlwaysEstimateNormalsPoints = 2'000'000;

}  // namespace subscan
