// What the binding files of the Python module share: the types that cross between them and
// the functions that add each part of the API to the module.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <pybind11/pybind11.h>

#include "core/Camera.h"
#include "core/LocalSpacing.h"
#include "core/PointCloud.h"
#include "core/SensorView.h"
#include "render/RenderSettings.h"

namespace subscan::python {

/// A subscan.Cloud: an immutable PointCloud (the Renderer and the array views may share it),
/// where it came from, and its spacing h, estimated once on first use.
class CloudData {
  public:
    CloudData(PointCloud cloud, std::string format) noexcept
        : cloud_(std::move(cloud)), format_(std::move(format)) {}

    const PointCloud& cloud() const { return cloud_; }
    /// "ply", "las", "pcd", "xyz", "e57", "off", "synthetic" from subscan.load; "numpy" or
    /// "open3d" for clouds made from arrays.
    const std::string& format() const { return format_; }
    /// estimateSpacing(cloud()), computed on the first call (call without the GIL: it may take
    /// half a second on millions of points; std::call_once makes concurrent first calls wait).
    double spacing() const;
    /// estimatePointSpacing with that h: the local spacing too where the renderer wants it,
    /// computed once for every Renderer of this cloud (call without the GIL).
    const PointSpacing& pointSpacing() const;
    /// normalsFor(cloud(), NormalSource::Auto): the normals the CLI's renderer estimates by
    /// default (none where the cloud has its own, or is too large), computed once for every
    /// Renderer of this cloud (call without the GIL).
    const std::vector<glm::vec3>& estimatedNormals() const;

    /// framingBounds(cloud()), computed on the first call (a pass over a sample of the points:
    /// 10 ms for 10 M, which only a default camera needs).
    const Bounds& framed() const;

    /// Where the file says its sensor stood and an organised cloud's grid (subscan.load), for
    /// Camera.sensor; empty for clouds made from arrays.
    std::optional<SensorPose> sensor;
    OrganisedGrid grid;
    /// A streamed survey's view or overview (subscan.load with lod): each point's
    /// LoadedScan::levelSpacing, which the local spacing takes (set before any Renderer), and
    /// normals as `render` gives a streamed view (streamedNormals).
    bool streamed = false;
    std::vector<float> levelSpacing;

  private:
    PointCloud cloud_;
    std::string format_;
    mutable std::once_flag spacingOnce_;
    mutable SpacingSample sample_;  // h, and the distances that decide on the local spacing
    mutable std::once_flag pointSpacingOnce_;
    mutable PointSpacing pointSpacing_;
    mutable std::once_flag normalsOnce_;
    mutable std::vector<glm::vec3> estimatedNormals_;
    mutable std::once_flag framedOnce_;
    mutable Bounds framed_;
};

using CloudHandle = std::shared_ptr<CloudData>;

/// A subscan.Settings: the settings its sections (subscan.Settings.raster, ...) edit in place,
/// shared with them.
struct SettingsData {
    RenderSettings value;
};

using SettingsHandle = std::shared_ptr<SettingsData>;

/// What a `settings=` argument may be: a Settings, a dict in the settings file's layout, or
/// None for the defaults. Throws ValueError (dicts with bad values) or TypeError.
RenderSettings settingsArgument(const pybind11::handle& argument);

/// The up axis an `up=` argument ("auto", "y", "z" or "-y") names for `cloud`, as the CLI's
/// --up (upAxisForScan); ValueError for any other name.
UpAxis upAxisArgument(const std::string& up, const CloudData& cloud);

/// A 3-vector from any sequence of 3 finite numbers; ValueError naming `name` otherwise.
glm::dvec3 vectorArgument(const pybind11::handle& object, std::string_view name);
/// ValueError naming `name` unless low <= value <= high (NaN is outside every range).
void checkRange(double value, double low, double high, std::string_view name);

/// The path of a str or os.PathLike argument.
std::string pathArgument(const pybind11::handle& argument);

/// Python warnings (UserWarning), one per reader warning, as the CLI prints them on stderr.
void warnAll(const std::string& source, const std::vector<std::string>& warnings);

void bindCloud(pybind11::module_& module);
void bindCamera(pybind11::module_& module);
void bindSettings(pybind11::module_& module);
void bindRenderer(pybind11::module_& module);
void bindAnalysis(pybind11::module_& module);

}  // namespace subscan::python
