#include "io/laz/IntegerModels.h"

#include <algorithm>
#include <limits>

namespace subscan::laz {

IntegerModels::IntegerModels(std::uint32_t bits, std::uint32_t contexts) {
    if (bits > 0 && bits < 32) {
        correctorBits = bits;
        correctorRange = 1u << bits;
        correctorMin = -static_cast<std::int32_t>(correctorRange / 2);
    } else {
        correctorBits = 32;
        correctorRange = 0;
        correctorMin = std::numeric_limits<std::int32_t>::min();
    }
    kModels.assign(contexts, SymbolModel(correctorBits + 1));
    for (std::uint32_t k = 1; k <= correctorBits; ++k) {
        correctorModels.emplace_back(1u << std::min(k, kBitsHigh));
    }
}

void IntegerModels::reset() {
    for (SymbolModel& model : kModels) {
        model.reset();
    }
    correctorZero = BitModel{};
    for (SymbolModel& model : correctorModels) {
        model.reset();
    }
}

}  // namespace subscan::laz
