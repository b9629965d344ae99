// subscan.Cloud and subscan.load: numpy arrays in and out of the library's PointCloud.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <thread>

#include <sys/mman.h>

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <glm/vector_relational.hpp>

#include "core/Error.h"
#include "core/NormalEstimation.h"
#include "core/Spacing.h"
#include "io/ScanLoader.h"
#include "lod/NodeSelection.h"
#include "lod/NodeSource.h"
#include "python/Bindings.h"
#include "render/Renderer.h"

namespace py = pybind11;

namespace subscan::python {

double CloudData::spacing() const {
    std::call_once(spacingOnce_, [this] { sample_ = sampleSpacing(cloud_); });
    return sample_.h;
}

const PointSpacing& CloudData::pointSpacing() const {
    std::call_once(pointSpacingOnce_, [this] {
        spacing();
        pointSpacing_ = withLevelSpacing(estimatePointSpacing(cloud_, sample_), levelSpacing);
    });
    return pointSpacing_;
}

const std::vector<glm::vec3>& CloudData::estimatedNormals() const {
    std::call_once(normalsOnce_, [this] {
        estimatedNormals_ =
            normalsFor(cloud_, streamed ? streamedNormals(NormalSource::Auto) : NormalSource::Auto);
    });
    return estimatedNormals_;
}

const Bounds& CloudData::framed() const {
    std::call_once(framedOnce_, [this] { framed_ = framingBounds(cloud_); });
    return framed_;
}

glm::dvec3 vectorArgument(const py::handle& object, std::string_view name) {
    const auto array = py::array_t<double, py::array::forcecast>::ensure(object);
    if (!array || array.ndim() != 1 || array.shape(0) != 3) {
        throw py::value_error(fmt::format("{} must be 3 numbers", name));
    }
    const glm::dvec3 value(array.at(0), array.at(1), array.at(2));
    if (!std::isfinite(value.x) || !std::isfinite(value.y) || !std::isfinite(value.z)) {
        throw py::value_error(fmt::format("{} must be finite", name));
    }
    return value;
}

void checkRange(double value, double low, double high, std::string_view name) {
    if (!(value >= low && value <= high)) {
        throw py::value_error(fmt::format("{} {} is outside {}..{}", name, value, low, high));
    }
}

std::string pathArgument(const py::handle& argument) {
    try {
        return py::module_::import("os").attr("fspath")(argument).cast<std::string>();
    } catch (const py::error_already_set&) {
        throw py::type_error(
            fmt::format("expected a path (str or os.PathLike), not {}",
                        py::type::of(argument).attr("__name__").cast<std::string>()));
    } catch (const py::cast_error&) {
        throw py::type_error("expected a path as str, not bytes");
    }
}

void warnAll(const std::string& source, const std::vector<std::string>& warnings) {
    for (const std::string& warning : warnings) {
        PyErr_WarnEx(PyExc_UserWarning, fmt::format("{}: {}", source, warning).c_str(), 1);
    }
}

namespace {

/// A 2-D (or 1-D, as one column) numpy array of one of the types the loops read directly, with
/// its strides in bytes: the array is read where it lies, contiguous or not, without a copy.
struct Table {
    py::array array;  // keeps the data alive
    const char* data = nullptr;
    py::ssize_t rows = 0;
    py::ssize_t columns = 0;
    py::ssize_t rowStride = 0;
    py::ssize_t columnStride = 0;
    char kind = 'f';  // numpy's dtype kind: 'f' float, 'u' unsigned, 'i' signed
    py::ssize_t itemSize = 8;

    template <class T>
    T at(py::ssize_t row, py::ssize_t column) const {
        T value;
        std::memcpy(&value, data + row * rowStride + column * columnStride, sizeof(T));
        return value;
    }
    /// The value as a double, whatever the (accepted) element type.
    double number(py::ssize_t row, py::ssize_t column) const {
        if (kind == 'f') {
            return itemSize == 4 ? at<float>(row, column) : at<double>(row, column);
        }
        if (kind == 'u') {
            return itemSize == 1 ? at<std::uint8_t>(row, column)
                                 : static_cast<double>(at<std::uint64_t>(row, column));
        }
        return static_cast<double>(at<std::int64_t>(row, column));
    }
};

std::string dtypeName(const py::array& array) {
    return py::str(array.dtype()).cast<std::string>();
}

/// `object` as a table of `rows` (any when -1) rows and one of `columns` columns (a 1-D array
/// is one column when 1 is allowed). Float32 and float64 are read as they are; with
/// `keepIntegers`, so are uint8, int64 and uint64, other integers becoming int64; without, all
/// integers become float64, as do float16 and long double. Throws ValueError naming `name` for
/// anything else: wrong shape, no rows, complex, strings, objects, booleans.
Table tableOf(const py::handle& object, std::string_view name, py::ssize_t rows,
              std::initializer_list<py::ssize_t> columns, bool keepIntegers = false) {
    py::array array;
    try {
        array = py::array::ensure(object);
    } catch (const py::error_already_set&) {
    }
    if (!array) {
        throw py::value_error(
            fmt::format("{} is not an array (got {})", name,
                        py::type::of(object).attr("__name__").cast<std::string>()));
    }
    if (array.ndim() == 0) {
        // A scalar, None or a string that numpy made a 0-d array of.
        const std::string given = py::isinstance<py::array>(object) || py::hasattr(object, "dtype")
                                      ? "a scalar"
                                      : py::type::of(object).attr("__name__").cast<std::string>();
        throw py::value_error(fmt::format("{} must be an array, not {}", name, given));
    }
    std::string expected;
    for (const py::ssize_t count : columns) {
        expected += fmt::format("{}N×{}", expected.empty() ? "" : " or ", count);
    }
    const bool oneColumn = std::find(columns.begin(), columns.end(), 1) != columns.end();
    const bool shapeOk = (array.ndim() == 2 && std::find(columns.begin(), columns.end(),
                                                         array.shape(1)) != columns.end()) ||
                         (array.ndim() == 1 && oneColumn);
    if (!shapeOk) {
        std::string shape;
        for (py::ssize_t axis = 0; axis < array.ndim(); ++axis) {
            shape += fmt::format("{}{}", axis == 0 ? "" : "×", array.shape(axis));
        }
        throw py::value_error(fmt::format("{} must be an array of shape {}{}, not {}", name,
                                          expected, oneColumn ? " (or N)" : "",
                                          shape.empty() ? "a scalar" : shape));
    }
    if (array.shape(0) == 0) {
        throw py::value_error(fmt::format("{} is empty: a cloud needs at least one point", name));
    }
    if (rows >= 0 && array.shape(0) != rows) {
        throw py::value_error(
            fmt::format("{} has {} rows but points has {}", name, array.shape(0), rows));
    }
    const char kind = array.dtype().kind();
    const py::ssize_t itemSize = array.dtype().itemsize();
    if (kind != 'f' && kind != 'i' && kind != 'u') {
        throw py::value_error(
            fmt::format("{} must hold real numbers, not {}", name, dtypeName(array)));
    }
    if (!array.dtype().attr("isnative").cast<bool>()) {
        // Big-endian data (e.g. from a file read with '>f8'): the loops read native numbers.
        array = array.attr("astype")(array.dtype().attr("newbyteorder")("="));
    }
    const bool floats = kind == 'f' || !keepIntegers;
    const bool direct = floats ? kind == 'f' && (itemSize == 4 || itemSize == 8)
                               : (kind == 'u' && (itemSize == 1 || itemSize == 8)) ||
                                     (kind == 'i' && itemSize == 8);
    if (!direct) {
        array = array.attr("astype")(floats ? "float64" : "int64");
    }
    Table table;
    table.array = array;
    table.data = static_cast<const char*>(array.data());
    table.rows = array.shape(0);
    table.columns = array.ndim() == 2 ? array.shape(1) : 1;
    table.rowStride = array.strides(0);
    table.columnStride = array.ndim() == 2 ? array.strides(1) : 0;
    table.kind = array.dtype().kind();
    table.itemSize = array.dtype().itemsize();
    return table;
}

[[noreturn]] void throwBadPoint(const Table& points, py::ssize_t row) {
    throw py::value_error(
        fmt::format("points row {} is ({}, {}, {}): coordinates must be finite and within ±1e15",
                    row, points.number(row, 0), points.number(row, 1), points.number(row, 2)));
}

/// Backs `bytes` at `data` (a large vector's storage, not yet written) with transparent huge
/// pages where the kernel leaves that to madvise: the first writes then fault in 2 MiB pages,
/// not 4 KiB ones, which halves the cost of filling a fresh 100 MB array (numpy advises its
/// own large arrays the same way).
void adviseHugePages(const void* data, std::size_t bytes) {
#ifdef MADV_HUGEPAGE
    const std::uintptr_t page = 4096;
    const auto address = reinterpret_cast<std::uintptr_t>(data);
    const std::uintptr_t begin = (address + page - 1) / page * page;
    const std::uintptr_t end = (address + bytes) / page * page;
    if (bytes >= (std::size_t{4} << 20) && end > begin) {
        madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);  // a hint only
    }
#else
    (void)data;
    (void)bytes;
#endif
}

/// Has the kernel map (and zero) the pages of the last two thirds of a fresh array on a second
/// core while the caller fills the array from its start: zeroing fresh pages is half the cost
/// of a first write (numpy's copy pays it too), and this way the writer meets mapped pages
/// after its first third, where it has spent about what mapping the rest takes. The thread
/// is joined on destruction. Nothing happens below 16 MiB (where the thread would cost more
/// than it saves), without MADV_POPULATE_WRITE (Linux 5.14) or without a second core.
class PagesMappedAhead {
  public:
    PagesMappedAhead(const void* data, std::size_t bytes) {
#ifdef MADV_POPULATE_WRITE
        constexpr std::size_t kSmallest = std::size_t{16} << 20;  // a thread costs ~0.1 ms
        const std::uintptr_t page = 4096;
        const auto address = reinterpret_cast<std::uintptr_t>(data);
        const std::uintptr_t begin = (address + bytes / 3 + page - 1) / page * page;
        const std::uintptr_t end = (address + bytes) / page * page;
        if (bytes >= kSmallest && end > begin && std::thread::hardware_concurrency() > 1) {
            thread_ = std::jthread([begin, end] {
                // A hint only: where it fails, the writer's own faults map the pages.
                madvise(reinterpret_cast<void*>(begin), end - begin, MADV_POPULATE_WRITE);
            });
        }
#else
        (void)data;
        (void)bytes;
#endif
    }

  private:
    std::jthread thread_;
};

/// Appends what `convert(first, count, out)` writes for `total` items to `vector`, a chunk at
/// a time through a buffer that stays in the L1 cache: the vector's memory is written once, by
/// a memcpy, where resize() would first fill it with zeros and push_back() would keep its
/// bookkeeping in the loop. Its storage is reserved at once, advised into huge pages and
/// mapped ahead of the writes.
template <class Item, class Convert>
void appendConverted(std::vector<Item>& vector, std::size_t total, Convert&& convert) {
    vector.reserve(vector.size() + total);
    adviseHugePages(vector.data() + vector.size(), total * sizeof(Item));
    const PagesMappedAhead mappedAhead(vector.data() + vector.size(), total * sizeof(Item));
    constexpr std::size_t kChunk = 256;  // a multiple of 4 points (see kBlockValues)
    Item buffer[kChunk];
    for (std::size_t first = 0; first < total; first += kChunk) {
        const std::size_t count = std::min(kChunk, total - first);
        convert(first, count, buffer);
        vector.insert(vector.end(), buffer, buffer + count);
    }
}

bool withinLimits(const glm::dvec3& p) {
    // Also false for NaN.
    return std::abs(p.x) <= kMaxCoordinate && std::abs(p.y) <= kMaxCoordinate &&
           std::abs(p.z) <= kMaxCoordinate;
}

/// The first row that is NaN, infinite or beyond ±1e15 raises ValueError (what readers drop
/// with a warning is an error here: the caller made the array and can fix it).
template <class T>
void refuseBadRows(const Table& points) {
    for (py::ssize_t row = 0; row < points.rows; ++row) {
        if (!withinLimits({points.at<T>(row, 0), points.at<T>(row, 1), points.at<T>(row, 2)})) {
            throwBadPoint(points, row);
        }
    }
}

/// A C-contiguous array is converted in one pass over it, in blocks of 4 points: 12 values, a
/// whole number of 16-byte vectors of float or double, in which lane j of every block always
/// holds coordinate j % 3. So the pass needs no shuffles: each lane keeps its own minimum,
/// maximum and check sum, combined per coordinate at the end. GCC's vector extensions make it
/// SIMD on every x86-64 (SSE2) without intrinsics; left to itself the compiler kept the
/// accumulators in memory and the pass took twice as long.
constexpr std::size_t kBlockValues = 12;
template <class T>
struct Vector16Of;
template <>
struct Vector16Of<float> {
    typedef float type __attribute__((vector_size(16)));
};
template <>
struct Vector16Of<double> {
    typedef double type __attribute__((vector_size(16)));
};

/// The positions of a C-contiguous, aligned array of T, in one pass: exact bounds, and float
/// positions relative to `origin`, a point inside the bounds chosen before the pass (the
/// middle of a sample's bounds), so that each position is within one float32 step of the
/// cloud's extent of its exact value (readers re-centre on the exact middle in a second pass,
/// which halves that; one pass is what lets a numpy array in at the cost of a copy). False
/// when a value is NaN, infinite or beyond ±1e15.
template <class T>
bool convertContiguous(const T* p, std::size_t n, PointCloud& cloud) {
    using Vector = typename Vector16Of<T>::type;
    constexpr std::size_t kLanes = sizeof(Vector) / sizeof(T);
    constexpr std::size_t kVectors = kBlockValues / kLanes;
    constexpr T kInfinity = std::numeric_limits<T>::infinity();

    // The origin: the middle of the bounds of up to 4096 evenly spread rows (any valid ones).
    Bounds sample;
    const std::size_t step = std::max<std::size_t>(1, n / 4096);
    for (std::size_t i = 0; i < n; i += step) {
        const glm::dvec3 point(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
        if (withinLimits(point)) {
            sample.add(point);
        }
    }
    const glm::dvec3 origin = sample.empty() ? glm::dvec3(0.0) : sample.center();
    double offsets[kBlockValues];
    for (std::size_t j = 0; j < kBlockValues; ++j) {
        offsets[j] = origin[static_cast<glm::length_t>(j % 3)];
    }

    // Min and max in T are exact: they pick values, they compute none.
    Vector low[kVectors], high[kVectors], check[kVectors];
    for (std::size_t k = 0; k < kVectors; ++k) {
        low[k] = Vector{} + kInfinity;
        high[k] = Vector{} - kInfinity;
        check[k] = Vector{};
    }
    glm::dvec3 lowest(std::numeric_limits<double>::infinity());
    glm::dvec3 highest(-std::numeric_limits<double>::infinity());
    double checkSum = 0.0;
    auto visitTail = [&](std::size_t j, double value) {
        const auto axis = static_cast<glm::length_t>(j % 3);
        lowest[axis] = std::min(lowest[axis], value);
        highest[axis] = std::max(highest[axis], value);
        checkSum += value - value;
    };
    appendConverted(cloud.positions, n, [&](std::size_t first, std::size_t count, glm::vec3* out) {
        const T* in = p + 3 * first;
        float* values = &out->x;
        const std::size_t blocks = 3 * count / kBlockValues;
        // Local copies, so that the float stores below cannot alias them (the compiler then
        // keeps them in registers).
        Vector lows[kVectors], highs[kVectors], checks[kVectors];
        std::memcpy(lows, low, sizeof(low));
        std::memcpy(highs, high, sizeof(high));
        std::memcpy(checks, check, sizeof(check));
        for (std::size_t block = 0; block < blocks; ++block) {
            const T* v = in + kBlockValues * block;
            for (std::size_t k = 0; k < kVectors; ++k) {
                Vector vector;
                std::memcpy(&vector, v + kLanes * k, sizeof(vector));  // maybe unaligned for 16
                lows[k] = vector < lows[k] ? vector : lows[k];
                highs[k] = vector > highs[k] ? vector : highs[k];
                // v - v is 0 for finite v and NaN for NaN and ±inf; a NaN stays in the sum.
                checks[k] += vector - vector;
            }
            for (std::size_t j = 0; j < kBlockValues; ++j) {
                values[kBlockValues * block + j] =
                    static_cast<float>(static_cast<double>(v[j]) - offsets[j]);
            }
        }
        std::memcpy(low, lows, sizeof(low));
        std::memcpy(high, highs, sizeof(high));
        std::memcpy(check, checks, sizeof(check));
        for (std::size_t j = blocks * kBlockValues; j < 3 * count; ++j) {  // the last 0-3 points
            visitTail(j, in[j]);
            values[j] = static_cast<float>(static_cast<double>(in[j]) - offsets[j % 3]);
        }
    });
    for (std::size_t j = 0; j < kBlockValues; ++j) {
        const auto axis = static_cast<glm::length_t>(j % 3);
        lowest[axis] = std::min(lowest[axis], static_cast<double>(low[j / kLanes][j % kLanes]));
        highest[axis] = std::max(highest[axis], static_cast<double>(high[j / kLanes][j % kLanes]));
        checkSum += check[j / kLanes][j % kLanes];
    }
    const glm::dvec3 limit(kMaxCoordinate);
    if (!(checkSum == 0.0 && glm::all(glm::greaterThanEqual(lowest, -limit)) &&
          glm::all(glm::lessThanEqual(highest, limit)))) {
        return false;
    }
    cloud.bounds.min = lowest;
    cloud.bounds.max = highest;
    cloud.origin = origin;
    return true;
}

/// cloud.positions, .bounds and .origin from an N×3 table of T.
template <class T>
void convertPoints(const Table& points, PointCloud& cloud) {
    const auto n = static_cast<std::size_t>(points.rows);
    const bool contiguous = points.columnStride == sizeof(T) && points.rowStride == 3 * sizeof(T) &&
                            reinterpret_cast<std::uintptr_t>(points.data) % alignof(T) == 0;
    if (contiguous) {
        if (convertContiguous(reinterpret_cast<const T*>(points.data), n, cloud)) {
            return;
        }
        refuseBadRows<T>(points);  // throws
    }
    // Strided arrays (columns of a wider table, Fortran order, reversed): exact bounds first,
    // then float positions around their middle, as the readers store them.
    refuseBadRows<T>(points);
    for (py::ssize_t row = 0; row < points.rows; ++row) {
        cloud.bounds.add({points.at<T>(row, 0), points.at<T>(row, 1), points.at<T>(row, 2)});
    }
    cloud.origin = cloud.bounds.center();
    appendConverted(cloud.positions, n, [&](std::size_t first, std::size_t count, glm::vec3* out) {
        for (std::size_t i = 0; i < count; ++i) {
            const auto row = static_cast<py::ssize_t>(first + i);
            out[i] = glm::vec3(
                glm::dvec3(points.at<T>(row, 0), points.at<T>(row, 1), points.at<T>(row, 2)) -
                cloud.origin);
        }
    });
}

std::vector<Rgba8> colorsOf(const Table& colors) {
    const auto n = static_cast<std::size_t>(colors.rows);
    const bool alpha = colors.columns == 4;
    if (colors.kind == 'u' && colors.itemSize == 1 && colors.columnStride == 1 &&
        colors.rowStride == colors.columns) {
        // C-contiguous uint8, the common case: one tight loop.
        std::vector<Rgba8> result;
        const auto* p = reinterpret_cast<const std::uint8_t*>(colors.data);
        const std::size_t step = alpha ? 4 : 3;
        appendConverted(result, n, [&](std::size_t first, std::size_t count, Rgba8* out) {
            for (std::size_t i = 0; i < count; ++i) {
                const std::uint8_t* c = p + step * (first + i);
                out[i] = {c[0], c[1], c[2], alpha ? c[3] : std::uint8_t{255}};
            }
        });
        return result;
    }
    std::vector<Rgba8> result(n);
    if (colors.kind == 'u' && colors.itemSize == 1) {
        for (py::ssize_t row = 0; row < colors.rows; ++row) {
            result[static_cast<std::size_t>(row)] = {
                colors.at<std::uint8_t>(row, 0), colors.at<std::uint8_t>(row, 1),
                colors.at<std::uint8_t>(row, 2),
                alpha ? colors.at<std::uint8_t>(row, 3) : std::uint8_t{255}};
        }
        return result;
    }
    // Floats are sRGB-encoded values in 0..1 (Open3D's and matplotlib's convention), integers
    // 0..255.
    const bool unit = colors.kind == 'f';
    const double scale = unit ? 255.0 : 1.0;
    for (py::ssize_t row = 0; row < colors.rows; ++row) {
        std::uint8_t channel[4] = {0, 0, 0, 255};
        for (py::ssize_t c = 0; c < colors.columns; ++c) {
            const double value = colors.number(row, c);
            if (!(value >= 0.0 && value <= (unit ? 1.0 : 255.0))) {
                throw py::value_error(fmt::format("colors row {} has {}: {} colours must lie in {}",
                                                  row, value, unit ? "float" : "integer",
                                                  unit ? "0..1" : "0..255"));
            }
            channel[c] = static_cast<std::uint8_t>(std::lround(value * scale));
        }
        result[static_cast<std::size_t>(row)] = {channel[0], channel[1], channel[2], channel[3]};
    }
    return result;
}

template <class Vector>
void requireFinite(std::string_view name, const Vector& values, int columns) {
    for (std::size_t i = 0; i < values.size(); ++i) {
        for (int c = 0; c < columns; ++c) {
            if (!std::isfinite(values[i][c])) {
                throw py::value_error(
                    fmt::format("{} row {} is not finite (NaN or infinite)", name, i));
            }
        }
    }
}

std::vector<glm::vec3> normalsOf(const Table& normals) {
    std::vector<glm::vec3> result;
    result.reserve(static_cast<std::size_t>(normals.rows));
    for (py::ssize_t row = 0; row < normals.rows; ++row) {
        result.emplace_back(normals.number(row, 0), normals.number(row, 1), normals.number(row, 2));
    }
    requireFinite("normals", result, 3);
    return result;
}

std::vector<float> intensitiesOf(const Table& intensity) {
    std::vector<float> result;
    result.reserve(static_cast<std::size_t>(intensity.rows));
    for (py::ssize_t row = 0; row < intensity.rows; ++row) {
        const double value = intensity.number(row, 0);
        if (!std::isfinite(value)) {
            throw py::value_error(
                fmt::format("intensity row {} is not finite (NaN or infinite)", row));
        }
        result.push_back(static_cast<float>(value));
    }
    return result;
}

std::vector<Triangle> trianglesOf(const Table& triangles, std::size_t points) {
    if (triangles.kind == 'f') {
        throw py::value_error(fmt::format("triangles must hold integer vertex indices, not {}",
                                          dtypeName(triangles.array)));
    }
    std::vector<Triangle> result(static_cast<std::size_t>(triangles.rows));
    for (py::ssize_t row = 0; row < triangles.rows; ++row) {
        for (py::ssize_t c = 0; c < 3; ++c) {
            const double index = triangles.number(row, c);
            if (!(index >= 0.0 && index < static_cast<double>(points))) {
                throw py::value_error(fmt::format("triangles row {} uses vertex {}, outside 0..{}",
                                                  row, index, points - 1));
            }
            result[static_cast<std::size_t>(row)][static_cast<std::size_t>(c)] =
                static_cast<std::uint32_t>(index);
        }
    }
    return result;
}

/// Cloud(points, colors=None, intensity=None, normals=None, triangles=None).
CloudHandle cloudFromArrays(const py::handle& pointsArgument, const py::handle& colorsArgument,
                            const py::handle& intensityArgument, const py::handle& normalsArgument,
                            const py::handle& trianglesArgument, std::string format) {
    const Table points = tableOf(pointsArgument, "points", -1, {3});
    if (static_cast<std::uint64_t>(points.rows) > kMaxPoints) {
        throw py::value_error(
            fmt::format("points has {} rows; a cloud holds at most {}", points.rows, kMaxPoints));
    }
    PointCloud cloud;
    {
        // Without the GIL: other Python threads go on while millions of points are copied.
        const py::gil_scoped_release release;
        if (points.itemSize == 4) {
            convertPoints<float>(points, cloud);
        } else {
            convertPoints<double>(points, cloud);
        }
    }
    if (!colorsArgument.is_none()) {
        cloud.colors = colorsOf(tableOf(colorsArgument, "colors", points.rows, {3, 4}, true));
    }
    if (!normalsArgument.is_none()) {
        cloud.normals = normalsOf(tableOf(normalsArgument, "normals", points.rows, {3}));
    }
    if (!intensityArgument.is_none()) {
        cloud.intensities =
            intensitiesOf(tableOf(intensityArgument, "intensity", points.rows, {1}));
    }
    if (!trianglesArgument.is_none()) {
        cloud.triangles =
            trianglesOf(tableOf(trianglesArgument, "triangles", -1, {3}, true), cloud.size());
    }
    return std::make_shared<CloudData>(std::move(cloud), std::move(format));
}

/// A read-only numpy view of `count` rows of `columns` elements at `data`, `rowBytes` apart,
/// that keeps `owner` (the Cloud) alive.
template <class T>
py::array viewOf(const T* data, std::size_t count, std::size_t columns, std::size_t rowBytes,
                 const py::handle& owner) {
    std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(count)};
    std::vector<py::ssize_t> strides{static_cast<py::ssize_t>(rowBytes)};
    if (columns > 1) {
        shape.push_back(static_cast<py::ssize_t>(columns));
        strides.push_back(static_cast<py::ssize_t>(sizeof(T)));
    }
    py::array array(py::dtype::of<T>(), shape, strides, data, owner);
    array.attr("setflags")(py::arg("write") = false);
    return array;
}

/// cloud.points: file coordinates in float64 (origin + position), a new array.
py::array_t<double> pointsOf(const CloudData& data) {
    const PointCloud& cloud = data.cloud();
    py::array_t<double> points({static_cast<py::ssize_t>(cloud.size()), py::ssize_t{3}});
    double* out = points.mutable_data();
    {
        const py::gil_scoped_release release;
        for (std::size_t i = 0; i < cloud.size(); ++i) {
            const glm::dvec3 p = cloud.fileCoordinates(i);
            out[3 * i] = p.x;
            out[3 * i + 1] = p.y;
            out[3 * i + 2] = p.z;
        }
    }
    return points;
}

py::object importOpen3d(std::string_view caller) {
    try {
        return py::module_::import("open3d");
    } catch (const py::error_already_set& error) {
        if (!error.matches(PyExc_ImportError)) {
            throw;
        }
        throw py::import_error(
            fmt::format("{} needs Open3D, which is not importable (pip install open3d, or Debian's "
                        "python3-open3d)",
                        caller));
    }
}

CloudHandle fromOpen3d(const py::object& pcd) {
    const py::module_ numpy = py::module_::import("numpy");
    if (!py::hasattr(pcd, "points")) {
        throw py::value_error("Cloud.from_open3d needs an open3d.geometry.PointCloud");
    }
    const py::object points = numpy.attr("asarray")(pcd.attr("points"));
    auto has = [&](const char* method) {
        return py::hasattr(pcd, method) && pcd.attr(method)().cast<bool>();
    };
    const py::object colors =
        has("has_colors") ? numpy.attr("asarray")(pcd.attr("colors")) : py::object(py::none());
    const py::object normals =
        has("has_normals") ? numpy.attr("asarray")(pcd.attr("normals")) : py::object(py::none());
    return cloudFromArrays(points, colors, py::none(), normals, py::none(), "open3d");
}

py::object toOpen3d(const CloudHandle& data, const py::object& self) {
    const py::object open3d = importOpen3d("Cloud.to_open3d");
    const py::object vector3d = open3d.attr("utility").attr("Vector3dVector");
    py::object pcd = open3d.attr("geometry").attr("PointCloud")();
    pcd.attr("points") = vector3d(pointsOf(*data));
    const PointCloud& cloud = data->cloud();
    if (cloud.hasColors()) {
        // Open3D holds colours as float64 in 0..1.
        const py::object colors = self.attr("colors");
        pcd.attr("colors") = vector3d(colors.attr("astype")("float64").attr("__truediv__")(255.0));
    }
    if (cloud.hasNormals()) {
        pcd.attr("normals") = vector3d(self.attr("normals").attr("astype")("float64"));
    }
    return pcd;
}

CloudHandle load(const py::handle& pathObject, const std::string& lod,
                 const std::optional<Camera>& camera, std::uint64_t pointBudget) {
    const std::string source = pathArgument(pathObject);
    lod::LodMode mode;
    try {
        mode = lod::parseLodMode(lod);
    } catch (const Error& error) {
        throw py::value_error(error.what());
    }
    LoadedScan scan;
    bool streamed = false;
    {
        const py::gil_scoped_release release;
        const std::unique_ptr<lod::NodeSource> survey = lod::openStreamed(source, mode);
        if (survey) {
            streamed = true;
            scan = camera ? lod::loadStreamedScan(
                                *survey, lod::selectNodes(*survey, *camera,
                                                          lod::pointBudgetFor(pointBudget, true)))
                          : lod::loadStreamedOverview(*survey);
        } else {
            scan = loadScan(source);
        }
    }
    warnAll(source, scan.warnings);
    auto cloud = std::make_shared<CloudData>(std::move(scan.cloud), scan.format);
    cloud->sensor = std::move(scan.sensor);
    cloud->grid = std::move(scan.grid);
    cloud->streamed = streamed;
    cloud->levelSpacing = std::move(scan.levelSpacing);
    return cloud;
}

}  // namespace

void bindCloud(py::module_& module) {
    py::class_<CloudData, std::shared_ptr<CloudData>>(module, "Cloud", R"doc(
A point cloud: positions, and optionally colours, intensity, normals and (for meshes) triangles.
Immutable: a Renderer and the array views below share it.

Cloud(points, colors=None, intensity=None, normals=None, triangles=None)

points     N×3 real numbers (float64 or float32 are read in place, contiguous or not; other
           number types are converted once), in any units; finite and within ±1e15.
colors     N×3 or N×4 sRGB-encoded colours: uint8 (0..255), other integers (0..255), or
           floats (0..1, as Open3D and matplotlib hold them).
intensity  N or N×1 numbers, finite (kept as float32).
normals    N×3 numbers, finite (kept as float32; not normalised).
triangles  M×3 integer vertex indices (a mesh, for evaluate() and scan()).

Positions are stored as float32 relative to the middle of the bounds (as subscan's readers
store files), so `points` reads back within float32 precision of that offset.
Bad arrays (wrong shape, empty, NaN or infinite values, wrong types) raise ValueError.
)doc")
        .def(py::init([](const py::object& points, const py::object& colors,
                         const py::object& intensity, const py::object& normals,
                         const py::object& triangles) {
                 return cloudFromArrays(points, colors, intensity, normals, triangles, "numpy");
             }),
             py::arg("points"), py::arg("colors") = py::none(), py::arg("intensity") = py::none(),
             py::arg("normals") = py::none(), py::arg("triangles") = py::none())
        .def_static(
            "from_open3d", [](const py::object& pcd) { return fromOpen3d(pcd); }, py::arg("pcd"),
            "A Cloud from an open3d.geometry.PointCloud: its points, colours (0..1) and "
            "normals, copied.")
        .def(
            "to_open3d",
            [](const std::shared_ptr<CloudData>& self) { return toOpen3d(self, py::cast(self)); },
            "An open3d.geometry.PointCloud with this cloud's points (file coordinates), "
            "colours (as 0..1) and normals. Needs Open3D importable (ImportError otherwise).")
        .def_property_readonly(
            "points", [](const CloudData& self) { return pointsOf(self); },
            "N×3 float64, the points in their own coordinates: a new array (computed from the "
            "float32 positions and the float64 offset).")
        .def_property_readonly(
            "colors",
            [](const py::object& self) -> py::object {
                const PointCloud& cloud = self.cast<const CloudData&>().cloud();
                if (!cloud.hasColors()) {
                    return py::none();
                }
                return viewOf(&cloud.colors.front().r, cloud.size(), 3, sizeof(Rgba8), self);
            },
            "N×3 uint8 sRGB colours, or None: a read-only view into the cloud (no copy).")
        .def_property_readonly(
            "intensity",
            [](const py::object& self) -> py::object {
                const PointCloud& cloud = self.cast<const CloudData&>().cloud();
                if (!cloud.hasIntensities()) {
                    return py::none();
                }
                return viewOf(cloud.intensities.data(), cloud.size(), 1, sizeof(float), self);
            },
            "N float32 intensities as the file stored them, or None: a read-only view.")
        .def_property_readonly(
            "classification",
            [](const py::object& self) -> py::object {
                const PointCloud& cloud = self.cast<const CloudData&>().cloud();
                if (!cloud.hasClassifications()) {
                    return py::none();
                }
                return viewOf(cloud.classifications.data(), cloud.size(), 1, sizeof(std::uint8_t),
                              self);
            },
            "N uint8 ASPRS class codes (LAS, LAZ and COPC files: the 5-bit code of point "
            "formats 0-5, the 8-bit one of formats 6-10, without the flags), or None: a "
            "read-only view.")
        .def_property_readonly(
            "normals",
            [](const py::object& self) -> py::object {
                const PointCloud& cloud = self.cast<const CloudData&>().cloud();
                if (!cloud.hasNormals()) {
                    return py::none();
                }
                return viewOf(&cloud.normals.front().x, cloud.size(), 3, sizeof(glm::vec3), self);
            },
            "N×3 float32 normals, or None: a read-only view.")
        .def_property_readonly(
            "triangles",
            [](const py::object& self) -> py::object {
                const PointCloud& cloud = self.cast<const CloudData&>().cloud();
                if (cloud.triangles.empty()) {
                    return py::none();
                }
                return viewOf(cloud.triangles.front().data(), cloud.triangles.size(), 3,
                              sizeof(Triangle), self);
            },
            "M×3 uint32 vertex indices of a mesh's faces, or None: a read-only view.")
        .def_property_readonly(
            "spacing",
            [](const CloudData& self) {
                const py::gil_scoped_release release;
                return self.spacing();
            },
            "The point spacing h: the median distance to the nearest other point, estimated "
            "on up to 20,000 points (as `subscan info` reports it); 0 for fewer than two "
            "distinct points. Computed once, on first use.")
        .def_property_readonly(
            "bounds",
            [](const CloudData& self) {
                const Bounds& bounds = self.cloud().bounds;
                py::array_t<double> result(std::vector<py::ssize_t>{2, 3});
                auto out = result.mutable_unchecked<2>();
                for (int axis = 0; axis < 3; ++axis) {
                    out(0, axis) = bounds.min[axis];
                    out(1, axis) = bounds.max[axis];
                }
                return result;
            },
            "2×3 float64: the smallest and the largest coordinates (lo, hi = cloud.bounds).")
        .def_property_readonly("format", &CloudData::format,
                               "Where the cloud came from: the file format ('ply', 'las', "
                               "'pcd', 'xyz', 'e57', 'off'), 'synthetic', 'numpy' or 'open3d'.")
        .def(
            "estimate_normals",
            [](const CloudData& self, const py::object& sensorArgument) {
                PointCloud cloud = self.cloud();
                std::optional<glm::dvec3> sensor;
                if (!sensorArgument.is_none()) {
                    sensor = vectorArgument(sensorArgument, "sensor");
                } else if (self.sensor) {
                    sensor = self.sensor->position;
                }
                {
                    const py::gil_scoped_release release;
                    cloud.normals = estimateNormals(cloud, sensor);
                }
                auto result = std::make_shared<CloudData>(std::move(cloud), self.format());
                result->sensor = self.sensor;
                result->grid = self.grid;
                return result;
            },
            py::arg("sensor") = py::none(),
            R"doc(A copy of this cloud with normals estimated from each point's nearest neighbours, as
the renderer estimates them for a cloud without its own (PCA over the 12 to 48 neighbours the
point's lie flattest in; in place of any the cloud has). They face `sensor` (x, y, z in the
cloud's coordinates), else the sensor the file recorded (a PCD VIEWPOINT, an E57 pose); without
either their sign is arbitrary. Clouds are immutable: use the returned one, e.g.
cloud = cloud.estimate_normals().)doc")
        .def("__len__", [](const CloudData& self) { return self.cloud().size(); })
        .def("__repr__", [](const CloudData& self) {
            const PointCloud& cloud = self.cloud();
            std::string attributes;
            for (const auto& [present, name] :
                 {std::pair{cloud.hasColors(), "colors"},
                  std::pair{cloud.hasIntensities(), "intensity"},
                  std::pair{cloud.hasClassifications(), "classification"},
                  std::pair{cloud.hasNormals(), "normals"},
                  std::pair{!cloud.triangles.empty(), "triangles"}}) {
                if (present) {
                    attributes += fmt::format(", {}", name);
                }
            }
            return fmt::format("<subscan.Cloud of {} points ({}{})>", cloud.size(), self.format(),
                               attributes);
        });

    module.def("load", &load, py::arg("path"), py::arg("lod") = "off",
               py::arg("camera") = py::none(), py::arg("point_budget") = 0, R"doc(
Loads a scan: a file in any format subscan reads (PLY, LAS, LAZ, COPC, E57, PCD, XYZ/PTS/CSV,
OFF), or 'synthetic:NAME[?points=N][&noise=X]' (sphere, torus, box-with-hole, sculpture).
The reader's warnings (e.g. dropped NaN points) become Python warnings. Raises subscan.Error
with the CLI's sentence when the file cannot be read. Runs without the GIL.

lod="auto" or "on" streams a COPC file or an EPT dataset (an ept.json or its folder) as
`subscan render` does: with `camera`, the octree nodes that view shows within `point_budget`
points (0: 1,000,000, the software renderer's default); without, the survey's top levels
(about 200,000 points, to frame a Camera by). "auto" loads other files whole, "on" refuses
them; "off" (the default) loads every file whole.
)doc");
}

}  // namespace subscan::python
