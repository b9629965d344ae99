#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "io/ByteOrder.h"
#include "io/laz/ArithmeticModels.h"
#include "io/laz/ItemCoding.h"
#include "io/laz/LazItems.h"

// What the decoders and the encoders of LASzip's version 3 items (layered chunks of LAS 1.4
// points: POINT14, RGB14, RGBNIR14, BYTE14) share: the point's fields, the layers, the contexts
// and each scanner channel's state. Written from Isenburg's LAS 1.4 compression design and the
// behaviour of the reference coder.
namespace subscan::laz {

/// LAS 1.4 points have four scanner channels; each has its own models and last values.
inline constexpr std::size_t kScannerChannels = 4;

/// (number of returns, return number) -> one of 6 contexts, for 4-bit return fields (LASzip's
/// number_return_map_6ctx).
inline constexpr std::uint8_t kReturnMap6[16][16] = {
    {0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5},
    {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
    {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3},
    {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4},
    {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
    {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};

/// Distance of the return from the last one, capped at 7 (number_return_level_8ctx).
inline std::uint32_t returnLevel8(std::uint32_t numberOfReturns, std::uint32_t returnNumber) {
    const std::uint32_t distance = numberOfReturns > returnNumber ? numberOfReturns - returnNumber
                                                                  : returnNumber - numberOfReturns;
    return distance < 7 ? distance : 7;
}

/// The fields of a LAS 1.4 point (formats 6-10, first 30 bytes).
struct Point14 {
    std::int32_t x = 0, y = 0, z = 0;
    std::uint16_t intensity = 0;
    std::uint32_t returnNumber = 0, numberOfReturns = 0;
    std::uint32_t classificationFlags = 0, scannerChannel = 0, scanDirection = 0, edge = 0;
    std::uint32_t classification = 0, userData = 0;
    std::int16_t scanAngle = 0;
    std::uint16_t pointSourceId = 0;
    std::uint64_t gpsTimeBits = 0;
    bool gpsTimeChanged = false;  // coder state: whether this point's time differed

    static Point14 load(const std::byte* p) {
        Point14 point;
        point.x = loadLittleEndian<std::int32_t>(p);
        point.y = loadLittleEndian<std::int32_t>(p + 4);
        point.z = loadLittleEndian<std::int32_t>(p + 8);
        point.intensity = loadLittleEndian<std::uint16_t>(p + 12);
        const auto returns = static_cast<std::uint32_t>(p[14]);
        point.returnNumber = returns & 15;
        point.numberOfReturns = returns >> 4;
        const auto flags = static_cast<std::uint32_t>(p[15]);
        point.classificationFlags = flags & 15;
        point.scannerChannel = (flags >> 4) & 3;
        point.scanDirection = (flags >> 6) & 1;
        point.edge = flags >> 7;
        point.classification = static_cast<std::uint32_t>(p[16]);
        point.userData = static_cast<std::uint32_t>(p[17]);
        point.scanAngle = loadLittleEndian<std::int16_t>(p + 18);
        point.pointSourceId = loadLittleEndian<std::uint16_t>(p + 20);
        point.gpsTimeBits = loadLittleEndian<std::uint64_t>(p + 22);
        return point;
    }

    void store(std::byte* p) const {
        storeLittleEndian(p, x);
        storeLittleEndian(p + 4, y);
        storeLittleEndian(p + 8, z);
        storeLittleEndian(p + 12, intensity);
        storeLittleEndian(p + 14, static_cast<std::uint8_t>(returnNumber | (numberOfReturns << 4)));
        storeLittleEndian(p + 15,
                          static_cast<std::uint8_t>(classificationFlags | (scannerChannel << 4) |
                                                    (scanDirection << 6) | (edge << 7)));
        storeLittleEndian(p + 16, static_cast<std::uint8_t>(classification));
        storeLittleEndian(p + 17, static_cast<std::uint8_t>(userData));
        storeLittleEndian(p + 18, scanAngle);
        storeLittleEndian(p + 20, pointSourceId);
        storeLittleEndian(p + 22, gpsTimeBits);
    }

    /// The flags as the flags layer codes them: classification flags, scan direction, edge.
    std::uint32_t flagBits() const {
        return (edge << 5) | (scanDirection << 4) | classificationFlags;
    }
    void setFlagBits(std::uint32_t flags) {
        edge = (flags >> 5) & 1;
        scanDirection = (flags >> 4) & 1;
        classificationFlags = flags & 15;
    }

    /// 2 for a first return, plus 1 for a last one (3: the only return).
    std::uint32_t firstLastContext() const {
        return (returnNumber == 1 ? 2u : 0u) + (returnNumber >= numberOfReturns ? 1u : 0u);
    }
    /// The context of the next point's change mask: first return (1), last return (2) and
    /// whether this point's GPS time changed (4).
    std::uint32_t changeContext() const {
        return (returnNumber == 1 ? 1u : 0u) + (returnNumber >= numberOfReturns ? 2u : 0u) +
               (gpsTimeChanged ? 4u : 0u);
    }
};

/// POINT14's nine layers, in chunk order.
enum Point14Layer : std::size_t {
    kChannelReturnsXY,
    kZ,
    kClassification,
    kFlags,
    kIntensity,
    kScanAngle,
    kUserData,
    kPointSource,
    kGpsTime,
    kPoint14Layers
};

/// Bits of POINT14's change mask, the first symbol of every point after the first.
namespace point14_change {
inline constexpr std::uint32_t kReturnNumber = 3;  // 0 same, 1 one up, 2 one down, 3 coded
inline constexpr std::uint32_t kNumberOfReturns = 1u << 2;
inline constexpr std::uint32_t kScanAngle = 1u << 3;
inline constexpr std::uint32_t kGpsTime = 1u << 4;
inline constexpr std::uint32_t kPointSource = 1u << 5;
inline constexpr std::uint32_t kScannerChannel = 1u << 6;
}  // namespace point14_change

/// What POINT14 keeps per scanner channel: the last point, the predictors and the models.
/// `IntegerCoder` and `GpsTimeCoder` are the encoding or the decoding ones.
template <class IntegerCoder, class GpsTimeCoder>
struct Point14ChannelState {
    bool used = false;
    Point14 last;
    std::array<std::uint16_t, 8> lastIntensities{};
    std::array<Median5, 12> xDiffMedians{};
    std::array<Median5, 12> yDiffMedians{};
    std::array<std::int32_t, 8> lastZ{};

    std::array<SymbolModel, 8> changedValues{SymbolModel(128), SymbolModel(128), SymbolModel(128),
                                             SymbolModel(128), SymbolModel(128), SymbolModel(128),
                                             SymbolModel(128), SymbolModel(128)};
    SymbolModel scannerChannel{3};
    LazySymbolModels numberOfReturns{16, 16};
    SymbolModel returnNumberGpsSame{13};
    LazySymbolModels returnNumber{16, 16};
    IntegerCoder dx{32, 2};
    IntegerCoder dy{32, 22};
    IntegerCoder z{32, 20};
    LazySymbolModels classifications{64, 256};
    LazySymbolModels flags{64, 64};
    LazySymbolModels userData{64, 256};
    IntegerCoder intensity{16, 4};
    IntegerCoder scanAngle{16, 2};
    IntegerCoder pointSource{16, 1};
    GpsTimeCoder gpsTime;

    /// Starts the channel from `from`: the chunk's first point, or the last point of the channel
    /// the stream switched from. Copies `from` first: it may be this state's own last point.
    void reset(const Point14& from) {
        const Point14 start = from;
        for (SymbolModel& model : changedValues) {
            model.reset();
        }
        scannerChannel.reset();
        numberOfReturns.reset();
        returnNumberGpsSame.reset();
        returnNumber.reset();
        dx.reset();
        dy.reset();
        for (std::size_t i = 0; i < xDiffMedians.size(); ++i) {
            xDiffMedians[i].reset();
            yDiffMedians[i].reset();
        }
        z.reset();
        lastZ.fill(start.z);
        classifications.reset();
        flags.reset();
        userData.reset();
        intensity.reset();
        lastIntensities.fill(start.intensity);
        scanAngle.reset();
        pointSource.reset();
        gpsTime.reset(start.gpsTimeBits);
        last = start;
        last.gpsTimeChanged = false;
        used = true;
    }

    /// The y coder's context after x was coded with k bits.
    std::uint32_t yContext(bool singleReturn) const {
        const std::uint32_t k = dx.lastK();
        return (singleReturn ? 1u : 0u) + (k < 20 ? k & ~1u : 20u);
    }
    /// The z coder's context after x and y were coded.
    std::uint32_t zContext(bool singleReturn) const {
        const std::uint32_t k = (dx.lastK() + dy.lastK()) / 2;
        return (singleReturn ? 1u : 0u) + (k < 18 ? k & ~1u : 18u);
    }
};

/// POINT14's per-channel states (made when a channel first occurs) and the current channel.
template <class State>
class Point14Channels {
  public:
    /// Starts a chunk on the channel of its first point.
    void start(const Point14& first) {
        for (std::optional<State>& state : states_) {
            if (state) {
                state->used = false;
            }
        }
        current_ = first.scannerChannel;
        begin(current_, first);
    }
    /// Whether `channel` occurred in the chunk so far.
    bool seen(std::uint32_t channel) const { return states_[channel] && states_[channel]->used; }
    /// Makes `channel` current; one new to the chunk continues from `from`, the last point of
    /// the channel switched from.
    void switchTo(std::uint32_t channel, const Point14& from) {
        if (!seen(channel)) {
            begin(channel, from);
        }
        current_ = channel;
    }
    std::uint32_t currentChannel() const { return current_; }
    State& current() { return *states_[current_]; }
    State& operator[](std::uint32_t channel) { return *states_[channel]; }

  private:
    void begin(std::uint32_t channel, const Point14& from) {
        if (!states_[channel]) {
            states_[channel].emplace();
        }
        states_[channel]->reset(from);
    }

    std::array<std::optional<State>, kScannerChannels> states_;
    std::uint32_t current_ = 0;
};

/// Shared by RGB14, RGBNIR14 and BYTE14: the last values per context (see LazItems.h), started
/// from the previous context's when a context first occurs. As in the reference coder, a switch
/// to a context already seen in this chunk keeps predicting from the previous context's last
/// values (and updates those), so files written by it decode identically.
template <class Last>
struct ChannelLastValues {
    std::array<Last, kScannerChannels> last{};
    std::array<bool, kScannerChannels> used{};
    std::uint32_t current = 0;

    void start(const Last& first, std::uint32_t context) {
        used.fill(false);
        current = context;
        last[current] = first;
        used[current] = true;
    }
    /// Returns the index of the last values to predict from and update; `fresh` is set when the
    /// channel's models must restart.
    std::uint32_t follow(std::uint32_t context, bool& fresh) {
        fresh = false;
        std::uint32_t values = current;
        if (context != current) {
            const std::uint32_t previous = current;
            current = context;
            if (!used[current]) {
                last[current] = last[previous];
                used[current] = true;
                fresh = true;
                values = current;
            }
        }
        return values;
    }
};

/// RGBNIR14's models of one channel: RGB14's and those of the NIR layer (which bytes changed,
/// and each byte's difference).
struct RgbNirModels {
    RgbModels rgb;
    SymbolModel nirChangedBytes{4};
    std::array<SymbolModel, 2> nirDifferences{SymbolModel(256), SymbolModel(256)};
    void reset() {
        rgb.reset();
        nirChangedBytes.reset();
        nirDifferences[0].reset();
        nirDifferences[1].reset();
    }
};

/// BYTE14's models: one per extra byte and scanner channel.
class Byte14Models {
  public:
    explicit Byte14Models(std::size_t count)
        : count_(count), models_(kScannerChannels * count, SymbolModel(256)) {}

    SymbolModel& of(std::uint32_t channel, std::size_t byte) {
        return models_[channel * count_ + byte];
    }
    /// Back to the initial state, for the channel's first point in a chunk.
    void reset(std::uint32_t channel) {
        for (std::size_t i = 0; i < count_; ++i) {
            of(channel, i).reset();
        }
    }

  private:
    std::size_t count_;
    std::vector<SymbolModel> models_;  // channel-major
};

/// The coder of a layered chunk's `item`, one of the four coder types (POINT14, RGB14,
/// RGBNIR14, BYTE14 in that order); nullptr for any other item.
template <class Base, class Point14Coder, class Rgb14Coder, class RgbNir14Coder, class Byte14Coder>
std::unique_ptr<Base> makeLayeredItemCoder(const ItemSpec& item) {
    switch (item.type) {
        case ItemType::Point14:
            return std::make_unique<Point14Coder>();
        case ItemType::Rgb14:
            return std::make_unique<Rgb14Coder>();
        case ItemType::RgbNir14:
            return std::make_unique<RgbNir14Coder>();
        case ItemType::Byte14:
            return std::make_unique<Byte14Coder>(item.size);
        default:
            return nullptr;
    }
}

inline std::array<std::uint16_t, 3> loadRgb(const std::byte* item) {
    return {loadLittleEndian<std::uint16_t>(item), loadLittleEndian<std::uint16_t>(item + 2),
            loadLittleEndian<std::uint16_t>(item + 4)};
}

inline std::array<std::uint16_t, 4> loadRgbNir(const std::byte* item) {
    return {loadLittleEndian<std::uint16_t>(item), loadLittleEndian<std::uint16_t>(item + 2),
            loadLittleEndian<std::uint16_t>(item + 4), loadLittleEndian<std::uint16_t>(item + 6)};
}

}  // namespace subscan::laz
