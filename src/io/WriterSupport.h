#pragma once

#include <bit>
#include <cstddef>
#include <cstring>
#include <ostream>
#include <string>
#include <vector>

#include "core/PointCloud.h"

namespace subscan {

/// Whether float would round the cloud's file coordinates by more than the data's own
/// resolution, but no less than memory keeps (floats relative to the centre, unless
/// PointCloud::positionResiduals give back what they lost): half a step of
/// the file's grid (PointCloud::coordinateStep: a LAS scale, a text's decimals); nothing where
/// the file held doubles; else, for floats, a millionth of the extent. UTM coordinates, where a
/// float step is half a metre, are so; the writers of formats that can choose (PLY, PCD) then
/// store doubles.
bool needsDoubleCoordinates(const PointCloud& cloud);

/// Whether any point's colour has an alpha below 255 (only PLY stores alpha).
bool hasTranslucentColors(const PointCloud& cloud);

/// Appends the bytes of `value` in little-endian order (the order of every binary format we
/// write).
template <class T>
void appendLittleEndian(std::string& out, T value) {
    static_assert(std::endian::native == std::endian::little,
                  "the writers copy values in memory order as little-endian");
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out.append(bytes, sizeof(T));
}

template <class T>
void appendLittleEndian(std::vector<std::byte>& out, T value) {
    static_assert(std::endian::native == std::endian::little,
                  "the writers copy values in memory order as little-endian");
    const std::size_t at = out.size();
    out.resize(at + sizeof(T));
    std::memcpy(out.data() + at, &value, sizeof(T));
}

/// Collects a file's bytes and hands them to the stream a few megabytes at a time: a big cloud
/// needs neither a copy of the whole file in memory nor a stream call per value.
class ChunkedOutput {
  public:
    explicit ChunkedOutput(std::ostream& stream) : stream_(stream) {}

    std::string& buffer() { return buffer_; }
    template <class T>
    void append(T value) {
        appendLittleEndian(buffer_, value);
    }
    /// x, y, z as double or as float (see needsDoubleCoordinates).
    void appendPosition(const glm::dvec3& position, bool doubles) {
        for (int axis = 0; axis < 3; ++axis) {
            if (doubles) {
                append(position[axis]);
            } else {
                append(static_cast<float>(position[axis]));
            }
        }
    }
    /// Call after each record: passes the buffer on once it holds a chunk.
    void flushIfFull() {
        if (buffer_.size() >= kChunkBytes) {
            flush();
        }
    }
    /// Passes on what is left; call once at the end (not in a destructor, so that a failed write
    /// stops at once).
    void flush() {
        stream_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
        buffer_.clear();
    }

  private:
    static constexpr std::size_t kChunkBytes = std::size_t{4} << 20;
    std::ostream& stream_;
    std::string buffer_;
};

}  // namespace subscan
