#pragma once

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include <glm/common.hpp>

#include "io/PointRecordSource.h"

namespace subscan::test {

/// Point records held in memory, handed out in pieces like a file's; the bounds are the
/// records' own.
class MemoryRecordSource : public PointRecordSource {
  public:
    MemoryRecordSource(std::vector<std::byte> records, const PointRecordFormat& format,
                       const Quantization& quantization)
        : records_(std::move(records)), length_(format.recordLength()) {
        info_.name = "memory";
        info_.format = format;
        info_.pointCount = records_.size() / length_;
        info_.quantization = quantization;
        info_.min = glm::dvec3(1e300);
        info_.max = glm::dvec3(-1e300);
        for (std::size_t i = 0; i < info_.pointCount; ++i) {
            info_.min = glm::min(info_.min, position(i));
            info_.max = glm::max(info_.max, position(i));
        }
    }

    const PointRecordSourceInfo& info() const override { return info_; }
    std::size_t read(std::vector<std::byte>& records, std::size_t maxPoints) override {
        const std::size_t count = std::min(maxPoints, info_.pointCount - next_);
        records.insert(records.end(), records_.begin() + next_ * length_,
                       records_.begin() + (next_ + count) * length_);
        next_ += count;
        ++reads_;
        return count;
    }
    void rewind() override { next_ = 0; }

    glm::dvec3 position(std::size_t i) const {
        std::int32_t stored[3];
        std::memcpy(stored, records_.data() + i * length_, sizeof stored);
        return glm::dvec3(stored[0], stored[1], stored[2]) * info_.quantization.scale +
               info_.quantization.offset;
    }
    /// How many times read() was called (a source read twice is read in two passes).
    std::size_t reads() const { return reads_; }
    PointRecordSourceInfo& mutableInfo() { return info_; }

  private:
    std::vector<std::byte> records_;
    std::size_t length_;
    PointRecordSourceInfo info_;
    std::size_t next_ = 0;
    std::size_t reads_ = 0;
};

}  // namespace subscan::test
