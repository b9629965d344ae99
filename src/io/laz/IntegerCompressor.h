#pragma once

#include <cstdint>

#include "io/laz/ArithmeticEncoder.h"
#include "io/laz/IntegerModels.h"

namespace subscan::laz {

/// LASzip's predictive integer encoder (see IntegerModels.h), the mirror of the
/// IntegerDecompressor of the same bits and contexts.
class IntegerCompressor : public IntegerCoderBase {
  public:
    explicit IntegerCompressor(std::uint32_t bits = 16, std::uint32_t contexts = 1)
        : IntegerCoderBase(bits, contexts) {}

    /// Codes `real` as `prediction` plus a corrector, folded into the value range (for fewer than
    /// 32 bits: into [-2^(bits-1), 2^(bits-1)), where the decoder's sum wraps back to `real`).
    void compress(ArithmeticEncoder& encoder, std::int32_t prediction, std::int32_t real,
                  std::uint32_t context = 0) {
        // Unsigned arithmetic: the difference wraps around int32 like the decoder's sum.
        auto corrector = static_cast<std::int32_t>(static_cast<std::uint32_t>(real) -
                                                   static_cast<std::uint32_t>(prediction));
        if (models_.correctorRange != 0) {
            const std::int32_t range = static_cast<std::int32_t>(models_.correctorRange);
            if (corrector < models_.correctorMin) {
                corrector += range;
            } else if (corrector >= models_.correctorMin + range) {
                corrector -= range;
            }
        }
        writeCorrector(encoder, corrector, models_.kModels[context]);
    }

  private:
    void writeCorrector(ArithmeticEncoder& encoder, std::int32_t corrector, SymbolModel& kModel);
};

}  // namespace subscan::laz
