#pragma once

#include <cstdint>

#include "io/laz/ArithmeticDecoder.h"
#include "io/laz/IntegerModels.h"

namespace subscan::laz {

/// LASzip's predictive integer decoder (see IntegerModels.h for the coding).
class IntegerDecompressor : public IntegerCoderBase {
  public:
    explicit IntegerDecompressor(std::uint32_t bits = 16, std::uint32_t contexts = 1)
        : IntegerCoderBase(bits, contexts) {}

    std::int32_t decompress(ArithmeticDecoder& decoder, std::int32_t prediction,
                            std::uint32_t context = 0) {
        // Unsigned arithmetic: the sum wraps like the encoder's instead of overflowing.
        auto real = static_cast<std::uint32_t>(prediction) +
                    static_cast<std::uint32_t>(readCorrector(decoder, models_.kModels[context]));
        if (models_.correctorRange != 0) {
            if (static_cast<std::int32_t>(real) < 0) {
                real += models_.correctorRange;
            } else if (real >= models_.correctorRange) {
                real -= models_.correctorRange;
            }
        }
        return static_cast<std::int32_t>(real);
    }

  private:
    std::int32_t readCorrector(ArithmeticDecoder& decoder, SymbolModel& kModel);
};

}  // namespace subscan::laz
