#pragma once

#include <array>
#include <cstdint>

#include "io/laz/ArithmeticEncoder.h"
#include "io/laz/IntegerCompressor.h"
#include "io/laz/ItemCoding.h"

// The encoding side of the building blocks in ItemCoding.h, for the layered (v3) items: the GPS
// time and RGB predictors, mirrors of GpsTimeDecoder and decodeRgb.
namespace subscan::laz {

/// POINT14's GPS time coder (asked only when the time changed).
class GpsTimeEncoder {
  public:
    void reset(std::uint64_t firstTimeBits) { state_.reset(firstTimeBits); }
    void encode(ArithmeticEncoder& encoder, std::uint64_t timeBits);

  private:
    void writeFullTime(ArithmeticEncoder& encoder, std::int64_t time);
    void writeMultiple(ArithmeticEncoder& encoder, std::int32_t diff);

    GpsTimeSequences<IntegerCompressor> state_{false};
};

/// Encodes colour `now` given the last one (R, G, B as stored, 16-bit) and returns the mask of
/// changed bytes it coded; LASzip writes the colour layer of a chunk where some mask is not 0
/// (the grey bit 6 counts: a constant colour that is not grey writes the layer too).
std::uint32_t encodeRgb(ArithmeticEncoder& encoder, RgbModels& models,
                        const std::array<std::uint16_t, 3>& last,
                        const std::array<std::uint16_t, 3>& now);

}  // namespace subscan::laz
