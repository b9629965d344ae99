#pragma once

#include <cstdint>
#include <vector>

// The adaptive models of LASzip's entropy coder (Isenburg 2013, "LASzip: lossless compression of
// LiDAR data"; an adaptive range coder after Said & Pearlman's FastAC with 32-bit state), shared
// by the ArithmeticEncoder and the ArithmeticDecoder: both sides must update a model on the same
// schedule, or they code different numbers. The constants below are part of the format.
namespace subscan::laz {

/// The interval is renormalised (a byte more written or read) whenever its length drops below
/// 2^24.
inline constexpr std::uint32_t kMinLength = 0x01000000u;
inline constexpr std::uint32_t kMaxLength = 0xFFFFFFFFu;
/// Probabilities of bit models have 13 bits, of symbol models 15 bits.
inline constexpr std::uint32_t kBitLengthShift = 13;
inline constexpr std::uint32_t kBitMaxCount = 1u << kBitLengthShift;
inline constexpr std::uint32_t kSymbolLengthShift = 15;
inline constexpr std::uint32_t kSymbolMaxCount = 1u << kSymbolLengthShift;

/// Adaptive model of one binary decision.
struct BitModel {
    std::uint32_t bit0Count = 1;
    std::uint32_t bitCount = 2;
    std::uint32_t bit0Probability = 1u << (kBitLengthShift - 1);
    std::uint32_t updateCycle = 4;
    std::uint32_t bitsUntilUpdate = 4;

    void update();
};

/// Adaptive model of a symbol in [0, symbols). Counts are rescaled into a cumulative
/// distribution on a schedule that starts every (symbols + 6) / 2 symbols and slows by 5/4 each
/// time up to (symbols + 6) * 8; alphabets above 16 symbols keep a lookup table into the
/// distribution so decoding starts near the answer.
class SymbolModel {
  public:
    explicit SymbolModel(std::uint32_t symbols);
    /// Back to the initial state (what a new chunk does), keeping the allocation.
    void reset();
    void update();

    std::uint32_t symbols;
    std::uint32_t lastSymbol;
    std::vector<std::uint32_t> distribution;  // lower bound of each symbol, in 2^-15
    std::vector<std::uint32_t> counts;
    std::vector<std::uint32_t> decoderTable;  // table size + 2 entries; empty up to 16 symbols
    std::uint32_t tableShift = 0;
    std::uint32_t totalCount = 0;
    std::uint32_t updateCycle = 0;
    std::uint32_t symbolsUntilUpdate = 0;
};

}  // namespace subscan::laz
