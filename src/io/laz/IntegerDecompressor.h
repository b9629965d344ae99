#pragma once

#include <cstdint>

#include "io/laz/ArithmeticDecoder.h"
#include "io/laz/IntegerModels.h"

namespace subscan::laz {

/// LASzip's predictive integer decoder (see IntegerModels.h for the coding).
class IntegerDecompressor {
  public:
    explicit IntegerDecompressor(std::uint32_t bits = 16, std::uint32_t contexts = 1)
        : models_(bits, contexts) {}

    /// Back to the initial state, as at the start of a chunk.
    void reset() {
        k_ = 0;
        models_.reset();
    }

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

    /// k of the last decompressed value; item coders use it to pick the next context.
    std::uint32_t lastK() const { return k_; }

  private:
    std::int32_t readCorrector(ArithmeticDecoder& decoder, SymbolModel& kModel);

    IntegerModels models_;
    std::uint32_t k_ = 0;
};

}  // namespace subscan::laz
