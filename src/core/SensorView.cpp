#include "core/SensorView.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <Eigen/Dense>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "core/Error.h"

namespace subscan {

namespace {

/// Near and far planes around points `nearest` to `farthest` deep: a margin either side, and
/// near no closer than 1e-4 of far (the depth buffers' precision; as orbitCamera).
void setDepthRange(Camera& camera, double nearest, double farthest) {
    camera.farPlane = 1.02 * farthest;
    camera.nearPlane = std::max(0.9 * nearest, 1e-4 * camera.farPlane);
}

/// A similarity moving `points` to their centroid and scaling their mean distance from it to
/// sqrt(dimension): what keeps the DLT's equations well conditioned.
template <int N>
Eigen::Matrix<double, N + 1, N + 1> normalising(
    const std::vector<Eigen::Matrix<double, N, 1>>& points) {
    Eigen::Matrix<double, N, 1> centroid = Eigen::Matrix<double, N, 1>::Zero();
    for (const auto& p : points) {
        centroid += p;
    }
    centroid /= static_cast<double>(points.size());
    double meanDistance = 0.0;
    for (const auto& p : points) {
        meanDistance += (p - centroid).norm();
    }
    meanDistance /= static_cast<double>(points.size());
    const double scale = meanDistance > 0.0 ? std::sqrt(double(N)) / meanDistance : 1.0;
    Eigen::Matrix<double, N + 1, N + 1> transform = Eigen::Matrix<double, N + 1, N + 1>::Identity();
    transform.template topLeftCorner<N, N>() *= scale;
    transform.template topRightCorner<N, 1>() = -scale * centroid;
    return transform;
}

}  // namespace

PinholeFit fitPinhole(const PointCloud& cloud, const OrganisedGrid& grid) {
    const std::size_t count = std::min(cloud.size(), grid.cellOfPoint.size());
    if (count < 6) {
        throw Error(fmt::format("the organised grid has {} valid points; a camera needs at least 6",
                                count));
    }
    std::vector<Eigen::Vector3d> points(count);
    std::vector<Eigen::Vector2d> pixels(count);
    for (std::size_t i = 0; i < count; ++i) {
        const glm::vec3& p = cloud.positions[i];
        points[i] = {p.x, p.y, p.z};
        const std::uint32_t cell = grid.cellOfPoint[i];
        // The middle of the cell, in pixels from the image's top-left corner.
        pixels[i] = {cell % static_cast<std::uint32_t>(grid.width) + 0.5,
                     cell / static_cast<std::uint32_t>(grid.width) + 0.5};
    }
    const Eigen::Matrix4d pointTransform = normalising<3>(points);
    const Eigen::Matrix3d pixelTransform = normalising<2>(pixels);

    // Each point gives two rows of A p = 0 for the 12 entries of the 3x4 projection; p is the
    // eigenvector of AᵀA with the least eigenvalue (summed point by point: A is never held).
    Eigen::Matrix<double, 12, 12> normal = Eigen::Matrix<double, 12, 12>::Zero();
    for (std::size_t i = 0; i < count; ++i) {
        const Eigen::Vector4d x = pointTransform * points[i].homogeneous();
        const Eigen::Vector3d u = pixelTransform * pixels[i].homogeneous();
        Eigen::Matrix<double, 12, 1> rowU = Eigen::Matrix<double, 12, 1>::Zero();
        Eigen::Matrix<double, 12, 1> rowV = Eigen::Matrix<double, 12, 1>::Zero();
        rowU.segment<4>(0) = x;
        rowU.segment<4>(8) = -u.x() * x;
        rowV.segment<4>(4) = x;
        rowV.segment<4>(8) = -u.y() * x;
        normal.selfadjointView<Eigen::Lower>().rankUpdate(rowU);
        normal.selfadjointView<Eigen::Lower>().rankUpdate(rowV);
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 12, 12>> solver(
        normal.selfadjointView<Eigen::Lower>());
    const Eigen::Matrix<double, 12, 1> p = solver.eigenvectors().col(0);
    Eigen::Matrix<double, 3, 4> normalised;
    normalised << p.segment<4>(0).transpose(), p.segment<4>(4).transpose(),
        p.segment<4>(8).transpose();
    Eigen::Matrix<double, 3, 4> projection = pixelTransform.inverse() * normalised * pointTransform;

    // The sign that puts the points in front (positive homogeneous depth).
    double depthSum = 0.0;
    for (const Eigen::Vector3d& point : points) {
        depthSum += projection.row(2).dot(point.homogeneous());
    }
    if (depthSum < 0.0) {
        projection = -projection;
    }
    const Eigen::Matrix3d m = projection.leftCols<3>();
    if (!(m.determinant() > 0.0)) {
        throw Error(
            "the organised grid is not the image of a pinhole camera (its projection "
            "mirrors or is singular)");
    }
    // M = K R (K upper triangular, R a rotation) by a QR decomposition of M reversed: with J the
    // row reversal, (J M)ᵀ = Q U gives M = (J Uᵀ J)(J Qᵀ).
    Eigen::Matrix3d reverse = Eigen::Matrix3d::Zero();
    reverse(0, 2) = reverse(1, 1) = reverse(2, 0) = 1.0;
    const Eigen::HouseholderQR<Eigen::Matrix3d> qr((reverse * m).transpose());
    const Eigen::Matrix3d upper = qr.matrixQR().triangularView<Eigen::Upper>();
    Eigen::Matrix3d intrinsics = reverse * upper.transpose() * reverse;
    Eigen::Matrix3d rotation = reverse * qr.householderQ().transpose();
    const Eigen::Matrix3d signs = intrinsics.diagonal().cwiseSign().asDiagonal();
    intrinsics = intrinsics * signs;
    rotation = signs * rotation;
    if (rotation.determinant() < 0.0) {
        rotation = -rotation;  // M > 0 and K > 0 leave only an overall sign
        intrinsics = -intrinsics;
    }
    const double scale = intrinsics(2, 2);
    intrinsics /= scale;
    const Eigen::Vector3d center = -m.inverse() * projection.col(3);

    PinholeFit fit;
    fit.focalX = intrinsics(0, 0);
    fit.focalY = intrinsics(1, 1);
    fit.principalPoint = {intrinsics(0, 2), intrinsics(1, 2)};
    double squaredError = 0.0;
    double nearest = std::numeric_limits<double>::infinity();
    double farthest = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
        const Eigen::Vector3d projected = projection * points[i].homogeneous();
        squaredError += (projected.hnormalized() - pixels[i]).squaredNorm();
        const double depth = rotation.row(2).dot(points[i] - center);
        nearest = std::min(nearest, depth);
        farthest = std::max(farthest, depth);
    }
    fit.rmsErrorPixels = std::sqrt(squaredError / static_cast<double>(count));
    if (!(nearest > 0.0) || !(fit.focalY > 0.0)) {
        throw Error("the organised grid is not the image of a pinhole camera (points behind it)");
    }

    // The sensor's axes are x right, y down, z forward; the camera's view space has y up and
    // looks down -z: rows 2 and 3 change sign.
    Camera& camera = fit.camera;
    camera.width = grid.width;
    camera.height = grid.height;
    camera.fovyDegrees = glm::degrees(2.0 * std::atan(0.5 * grid.height / fit.focalY));
    camera.principalOffsetPixels = fit.principalPoint - 0.5 * glm::dvec2(grid.width, grid.height);
    const glm::dvec3 eye = cloud.origin + glm::dvec3(center.x(), center.y(), center.z());
    glm::dmat4 view(1.0);
    for (int row = 0; row < 3; ++row) {
        const double sign = row == 0 ? 1.0 : -1.0;
        for (int column = 0; column < 3; ++column) {
            view[column][row] = sign * rotation(row, column);
        }
    }
    view = view * Camera::translation(-eye);
    camera.view = view;
    setDepthRange(camera, nearest, farthest);
    return fit;
}

UpAxis upAxisForScan(std::string_view up, std::string_view format, const PointCloud& cloud,
                     const OrganisedGrid& grid) {
    const UpAxis named = upAxisFor(up, format);
    if (up != "auto" || grid.empty()) {
        return named;
    }
    // A few thousand points spread over the grid tell its camera's up as well as all of them
    // would, and callers ask more than once (the camera, the colours): no full fit each time.
    constexpr std::size_t kFitPoints = 4096;
    const std::size_t count = std::min(cloud.size(), grid.cellOfPoint.size());
    const std::size_t stride = std::max<std::size_t>(1, count / kFitPoints);
    PointCloud sample;
    sample.origin = cloud.origin;
    OrganisedGrid sampleGrid{grid.width, grid.height, {}};
    for (std::size_t i = 0; i < count; i += stride) {
        sample.positions.push_back(cloud.positions[i]);
        sampleGrid.cellOfPoint.push_back(grid.cellOfPoint[i]);
    }
    try {
        const PinholeFit fit = fitPinhole(sample, sampleGrid);
        if (fit.rmsErrorPixels > kPinholeToleranceRmsPixels) {
            return named;
        }
        const glm::dvec3 pictureUp(glm::inverse(fit.camera.view) * glm::dvec4(0, 1, 0, 0));
        return glm::dot(glm::normalize(pictureUp), glm::dvec3(0, -1, 0)) > std::sqrt(0.5)
                   ? UpAxis::NegativeY
                   : named;
    } catch (const Error&) {
        return named;  // no camera to take it from: as viewFromSensor, the sensor's or none
    }
}

Camera sensorCamera(const PointCloud& cloud, const SensorPose& sensor, UpAxis up, int width,
                    int height, double fovyDegrees) {
    const Bounds framed = framingBounds(cloud);
    const glm::dvec3 target = framed.center();
    const double diagonal = glm::length(cloud.bounds.extent());
    const glm::dvec3 nearestInBox = glm::clamp(sensor.position, cloud.bounds.min, cloud.bounds.max);
    if (glm::length(sensor.position - nearestInBox) > 20.0 * std::max(diagonal, 1e-9)) {
        throw Error(
            fmt::format("the sensor position ({:.6g}, {:.6g}, {:.6g}) from {} is more than 20 "
                        "times the points' "
                        "extent away from them; give the sensor with --sensor X,Y,Z",
                        sensor.position.x, sensor.position.y, sensor.position.z, sensor.source));
    }
    Camera camera;
    camera.width = width;
    camera.height = height;
    camera.fovyDegrees = fovyDegrees;
    const OrbitFrame frame = orbitFrame(up);
    glm::dvec3 upVector = frame.up;
    glm::dvec3 direction = target - sensor.position;
    if (nearestInBox == sensor.position) {
        // A station inside its scene sees all round: look level, towards the middle's azimuth
        // (the middle itself may lie straight above, where a tower raises the box).
        direction -= glm::dot(direction, upVector) * upVector;
    }
    if (glm::length(direction) <= 1e-6 * std::max(diagonal, 1e-9)) {
        // At the middle of the points: look at the front.
        direction = -frame.front;
    }
    direction = glm::normalize(direction);
    if (const double along = glm::dot(direction, upVector); std::abs(along) > 0.9999) {
        // Looking (nearly) straight down or up: the picture's up is the limit the view's takes
        // there, the horizontal direction it looks in (away from it looking up), not a fixed
        // one that turned the picture where this began.
        const glm::dvec3 horizontal = direction - along * upVector;
        upVector = glm::length(horizontal) > 1e-12
                       ? (along < 0.0 ? 1.0 : -1.0) * glm::normalize(horizontal)
                       : -frame.front;
    }
    camera.view = glm::lookAt(sensor.position, sensor.position + direction, upVector);
    double nearest = std::numeric_limits<double>::infinity();
    double farthest = 0.0;
    const glm::dmat4 viewFromCloud = camera.viewFromCloud(cloud.origin);
    for (const glm::vec3& position : cloud.positions) {
        const double depth = -(viewFromCloud * glm::dvec4(glm::dvec3(position), 1.0)).z;
        if (depth > 0.0) {
            nearest = std::min(nearest, depth);
            farthest = std::max(farthest, depth);
        }
    }
    if (!(farthest > 0.0)) {
        farthest = std::max(diagonal, 1e-9);
        nearest = farthest;
    }
    setDepthRange(camera, nearest, farthest);
    return camera;
}

Camera viewFromSensor(const PointCloud& cloud, const OrganisedGrid& grid,
                      const std::optional<SensorPose>& pose, UpAxis up, int width, int height,
                      bool sizeGiven, double fovyDegrees, std::vector<std::string>& warnings) {
    if (!grid.empty()) {
        try {
            const PinholeFit fit = fitPinhole(cloud, grid);
            if (fit.rmsErrorPixels <= kPinholeToleranceRmsPixels) {
                Camera camera = fit.camera;
                if (sizeGiven) {
                    // The same field of view over the rows; the principal point scales with it.
                    camera.principalOffsetPixels *=
                        static_cast<double>(height) / static_cast<double>(camera.height);
                    camera.width = width;
                    camera.height = height;
                }
                return camera;
            }
            warnings.push_back(fmt::format(
                "the organised grid is no pinhole camera's image (it misses by {:.3g} pixels "
                "RMS); the sensor view looks from its position at the points instead",
                fit.rmsErrorPixels));
        } catch (const Error& error) {
            warnings.push_back(fmt::format(
                "{}; the sensor view looks from its position at the points instead", error.what()));
        }
    }
    if (!pose) {
        throw Error(
            "the scan records no sensor position (a PCD VIEWPOINT, an E57 pose or an organised "
            "grid); give one with --sensor X,Y,Z");
    }
    return sensorCamera(cloud, *pose, up, width, height, fovyDegrees);
}

}  // namespace subscan
