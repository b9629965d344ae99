#include "io/laz/IntegerDecompressor.h"

#include <algorithm>
#include <limits>

namespace subscan::laz {

IntegerDecompressor::IntegerDecompressor(std::uint32_t bits, std::uint32_t contexts) {
    if (bits > 0 && bits < 32) {
        correctorBits_ = bits;
        correctorRange_ = 1u << bits;
        correctorMin_ = -static_cast<std::int32_t>(correctorRange_ / 2);
    } else {
        correctorBits_ = 32;
        correctorRange_ = 0;
        correctorMin_ = std::numeric_limits<std::int32_t>::min();
    }
    kModels_.assign(contexts, SymbolModel(correctorBits_ + 1));
    for (std::uint32_t k = 1; k <= correctorBits_; ++k) {
        correctorModels_.emplace_back(1u << std::min(k, kBitsHigh));
    }
}

void IntegerDecompressor::reset() {
    k_ = 0;
    for (SymbolModel& model : kModels_) {
        model.reset();
    }
    correctorZero_ = BitModel{};
    for (SymbolModel& model : correctorModels_) {
        model.reset();
    }
}

std::int32_t IntegerDecompressor::readCorrector(ArithmeticDecoder& decoder, SymbolModel& kModel) {
    k_ = decoder.decodeSymbol(kModel);
    if (k_ == 0) {
        return static_cast<std::int32_t>(decoder.decodeBit(correctorZero_));
    }
    if (k_ >= 32) {
        return correctorMin_;
    }
    std::uint32_t c = decoder.decodeSymbol(correctorModels_[k_ - 1]);
    if (k_ > kBitsHigh) {
        const std::uint32_t lowBits = k_ - kBitsHigh;
        c = (c << lowBits) | decoder.readBits(lowBits);
    }
    // c in [0, 2^k): the upper half maps to positive correctors, the lower to negative ones.
    if (c >= (1u << (k_ - 1))) {
        return static_cast<std::int32_t>(c + 1);
    }
    return static_cast<std::int32_t>(c) - static_cast<std::int32_t>((1u << k_) - 1);
}

}  // namespace subscan::laz
