#pragma once

#include <cstdint>
#include <vector>

#include "io/laz/ArithmeticModels.h"

// LASzip's predictive integer coder codes a value as its prediction plus a corrector. The
// corrector is coded as k, the number of its significant bits (one adaptive symbol per context),
// then, for k > 0, the corrector's position within [-(2^k - 1), -2^(k-1)] or [2^(k-1) + 1, 2^k]:
// its top min(k, 8) bits as an adaptive symbol of model k, the rest raw; k = 0 is 0 or 1 (a bit
// model). Values live in a range of 2^bits (32: all of int32), so sums wrap around that range.
namespace subscan::laz {

/// What the IntegerCompressor and the IntegerDecompressor share: the range and the models.
struct IntegerModels {
    /// Bits of the corrector coded as an adaptive symbol; the rest of a larger k is raw.
    static constexpr std::uint32_t kBitsHigh = 8;

    explicit IntegerModels(std::uint32_t bits, std::uint32_t contexts);
    /// Back to the initial state, as at the start of a chunk.
    void reset();

    std::uint32_t correctorBits;
    std::uint32_t correctorRange;  // 0 for 32-bit values: the wrap of uint32 is the range
    std::int32_t correctorMin;
    std::vector<SymbolModel> kModels;  // one per context
    BitModel correctorZero;
    std::vector<SymbolModel> correctorModels;  // index k - 1
};

/// The part of the IntegerCompressor and the IntegerDecompressor that is the same: the models and
/// k of the last value coded.
class IntegerCoderBase {
  public:
    /// Back to the initial state, as at the start of a chunk.
    void reset() {
        k_ = 0;
        models_.reset();
    }

    /// k of the last value coded; item coders use it to pick the next context.
    std::uint32_t lastK() const { return k_; }

  protected:
    IntegerCoderBase(std::uint32_t bits, std::uint32_t contexts) : models_(bits, contexts) {}

    IntegerModels models_;
    std::uint32_t k_ = 0;
};

}  // namespace subscan::laz
