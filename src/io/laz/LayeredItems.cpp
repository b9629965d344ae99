// LASzip's version 3 item coders (layered chunks of LAS 1.4 points), written from Isenburg's
// LAS 1.4 compression design and the behaviour of the reference decoder: POINT14, RGB14,
// RGBNIR14 and BYTE14. Each field group has its own layer, and each of the four scanner
// channels its own models and last values.
#include <array>
#include <cstring>
#include <optional>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/laz/IntegerDecompressor.h"
#include "io/laz/ItemCoding.h"
#include "io/laz/LazItems.h"

namespace subscan::laz {

namespace {

constexpr std::size_t kChannels = 4;

template <class T>
void store(std::byte* p, T value) {
    std::memcpy(p, &value, sizeof(T));  // little-endian hosts only (checked in LazDecoder)
}

/// A layer's stream; an empty layer means its fields do not change within the chunk.
struct Layer {
    ArithmeticDecoder decoder;
    bool changes = false;

    void start(std::span<const std::byte> bytes) {
        changes = !bytes.empty();
        if (changes) {
            decoder.start(bytes);
        }
    }
};

// (number of returns, return number) -> one of 6 contexts, for 4-bit return fields (LASzip's
// number_return_map_6ctx).
constexpr std::uint8_t kReturnMap6[16][16] = {{0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5},
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
std::uint32_t returnLevel8(std::uint32_t numberOfReturns, std::uint32_t returnNumber) {
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
        laz::store(p, x);
        laz::store(p + 4, y);
        laz::store(p + 8, z);
        laz::store(p + 12, intensity);
        laz::store(p + 14, static_cast<std::uint8_t>(returnNumber | (numberOfReturns << 4)));
        laz::store(p + 15, static_cast<std::uint8_t>(classificationFlags | (scannerChannel << 4) |
                                                     (scanDirection << 6) | (edge << 7)));
        laz::store(p + 16, static_cast<std::uint8_t>(classification));
        laz::store(p + 17, static_cast<std::uint8_t>(userData));
        laz::store(p + 18, scanAngle);
        laz::store(p + 20, pointSourceId);
        laz::store(p + 22, gpsTimeBits);
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

/// What POINT14 keeps per scanner channel: the last point, the predictors and the models.
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
    IntegerDecompressor dx{32, 2};
    IntegerDecompressor dy{32, 22};
    IntegerDecompressor z{32, 20};
    LazySymbolModels classifications{64, 256};
    LazySymbolModels flags{64, 64};
    LazySymbolModels userData{64, 256};
    IntegerDecompressor intensity{16, 4};
    IntegerDecompressor scanAngle{16, 2};
    IntegerDecompressor pointSource{16, 1};
    GpsTimeDecoder gpsTime{false};

    void reset(const Point14& from) {
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
        lastZ.fill(from.z);
        classifications.reset();
        flags.reset();
        userData.reset();
        intensity.reset();
        lastIntensities.fill(from.intensity);
        scanAngle.reset();
        pointSource.reset();
        gpsTime.reset(from.gpsTimeBits);
        last = from;
        last.gpsTimeChanged = false;
        used = true;
    }
};

class Point14Decoder final : public LayeredItemDecoder {
  public:
    std::size_t layerCount() const override { return kPoint14Layers; }

    void start(const std::byte* item, std::span<const std::span<const std::byte>> layers,
               std::uint32_t& context) override {
        for (std::size_t i = 0; i < kPoint14Layers; ++i) {
            layers_[i].start(layers[i]);
        }
        for (std::optional<Point14ChannelState>& channel : channels_) {
            if (channel) {
                channel->used = false;
            }
        }
        const Point14 first = Point14::load(item);
        current_ = first.scannerChannel;
        context = current_;
        startChannel(current_, first);
    }

    void decode(std::byte* item, std::uint32_t& context) override {
        ArithmeticDecoder& xy = layers_[kChannelReturnsXY].decoder;
        if (!layers_[kChannelReturnsXY].changes) {
            throw Error("the LAZ chunk has more than one point but no coordinate layer");
        }
        Point14ChannelState* state = &*channels_[current_];
        Point14* last = &state->last;

        std::uint32_t previous = last->returnNumber == 1 ? 1 : 0;
        previous += last->returnNumber >= last->numberOfReturns ? 2 : 0;
        previous += last->gpsTimeChanged ? 4 : 0;
        const std::uint32_t changed = xy.decodeSymbol(state->changedValues[previous]);

        if (changed & (1u << 6)) {
            const std::uint32_t channel =
                (current_ + xy.decodeSymbol(state->scannerChannel) + 1) % kChannels;
            if (!channels_[channel] || !channels_[channel]->used) {
                startChannel(channel, *last);
            }
            current_ = channel;
            context = current_;
            state = &*channels_[current_];
            last = &state->last;
            last->scannerChannel = channel;
        }
        const bool pointSourceChanged = changed & (1u << 5);
        const bool gpsTimeChanged = changed & (1u << 4);
        const bool scanAngleChanged = changed & (1u << 3);

        const std::uint32_t lastN = last->numberOfReturns;
        const std::uint32_t lastR = last->returnNumber;
        std::uint32_t n = lastN;
        if (changed & (1u << 2)) {
            n = xy.decodeSymbol(state->numberOfReturns[lastN]);
            last->numberOfReturns = n;
        }
        std::uint32_t r = lastR;
        switch (changed & 3) {
            case 0:
                break;
            case 1:
                r = (lastR + 1) % 16;
                break;
            case 2:
                r = (lastR + 15) % 16;
                break;
            default:
                if (gpsTimeChanged) {
                    r = xy.decodeSymbol(state->returnNumber[lastR]);
                } else {
                    r = (lastR + xy.decodeSymbol(state->returnNumberGpsSame) + 2) % 16;
                }
                break;
        }
        last->returnNumber = r;

        const std::uint32_t m = kReturnMap6[n][r];
        const std::uint32_t l = returnLevel8(n, r);
        std::uint32_t firstLast = r == 1 ? 2 : 0;  // first return?
        firstLast += r >= n ? 1 : 0;               // last return?

        const std::uint32_t single = n == 1 ? 1 : 0;
        const std::size_t medianIndex = (m << 1) | (gpsTimeChanged ? 1 : 0);
        std::int32_t diff =
            state->dx.decompress(xy, state->xDiffMedians[medianIndex].get(), single);
        last->x = wrappingAdd(last->x, diff);
        state->xDiffMedians[medianIndex].add(diff);
        std::uint32_t k = state->dx.lastK();
        diff = state->dy.decompress(xy, state->yDiffMedians[medianIndex].get(),
                                    single + (k < 20 ? k & ~1u : 20));
        last->y = wrappingAdd(last->y, diff);
        state->yDiffMedians[medianIndex].add(diff);

        if (layers_[kZ].changes) {
            k = (state->dx.lastK() + state->dy.lastK()) / 2;
            last->z = state->z.decompress(layers_[kZ].decoder, state->lastZ[l],
                                          single + (k < 18 ? k & ~1u : 18));
            state->lastZ[l] = last->z;
        }
        if (layers_[kClassification].changes) {
            const std::uint32_t modelIndex =
                ((last->classification & 0x1F) << 1) + (firstLast == 3 ? 1 : 0);
            last->classification =
                layers_[kClassification].decoder.decodeSymbol(state->classifications[modelIndex]);
        }
        if (layers_[kFlags].changes) {
            const std::uint32_t lastFlags =
                (last->edge << 5) | (last->scanDirection << 4) | last->classificationFlags;
            const std::uint32_t flags =
                layers_[kFlags].decoder.decodeSymbol(state->flags[lastFlags]);
            last->edge = (flags >> 5) & 1;
            last->scanDirection = (flags >> 4) & 1;
            last->classificationFlags = flags & 15;
        }
        if (layers_[kIntensity].changes) {
            const std::size_t slot = (firstLast << 1) | (gpsTimeChanged ? 1 : 0);
            last->intensity = static_cast<std::uint16_t>(state->intensity.decompress(
                layers_[kIntensity].decoder, state->lastIntensities[slot], firstLast));
            state->lastIntensities[slot] = last->intensity;
        }
        if (layers_[kScanAngle].changes && scanAngleChanged) {
            last->scanAngle = static_cast<std::int16_t>(state->scanAngle.decompress(
                layers_[kScanAngle].decoder, last->scanAngle, gpsTimeChanged ? 1 : 0));
        }
        if (layers_[kUserData].changes) {
            last->userData =
                layers_[kUserData].decoder.decodeSymbol(state->userData[last->userData / 4]);
        }
        if (layers_[kPointSource].changes && pointSourceChanged) {
            last->pointSourceId = static_cast<std::uint16_t>(
                state->pointSource.decompress(layers_[kPointSource].decoder, last->pointSourceId));
        }
        if (layers_[kGpsTime].changes && gpsTimeChanged) {
            state->gpsTime.decode(layers_[kGpsTime].decoder);
            last->gpsTimeBits = state->gpsTime.timeBits();
        }
        last->store(item);
        last->gpsTimeChanged = gpsTimeChanged;
    }

  private:
    /// A channel's first point in the chunk continues from `from` (the first point, or the last
    /// point of the channel the stream switched from).
    void startChannel(std::uint32_t channel, const Point14& from) {
        if (!channels_[channel]) {
            channels_[channel].emplace();
        }
        const Point14 copy = from;  // `from` may live in the state being reset
        channels_[channel]->reset(copy);
    }

    std::array<Layer, kPoint14Layers> layers_;
    std::array<std::optional<Point14ChannelState>, kChannels> channels_;
    std::uint32_t current_ = 0;
};

/// Shared by RGB14, RGBNIR14 and BYTE14: the per-channel last values, started from the previous
/// channel's when a channel first occurs. As in the reference coder, a switch to a channel
/// already seen in this chunk keeps predicting from the previous channel's last values (and
/// updates those), so files written by it decode identically.
template <class Last>
struct ChannelLastValues {
    std::array<Last, kChannels> last{};
    std::array<bool, kChannels> used{};
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

class Rgb14Decoder : public LayeredItemDecoder {
  public:
    std::size_t layerCount() const override { return 1; }

    void start(const std::byte* item, std::span<const std::span<const std::byte>> layers,
               std::uint32_t& context) override {
        rgb_.start(layers[0]);
        lastValues_.start(loadRgb(item), context);
        models_[context].reset();
    }

    void decode(std::byte* item, std::uint32_t& context) override {
        bool fresh = false;
        const std::uint32_t values = lastValues_.follow(context, fresh);
        if (fresh) {
            models_[context].reset();
        }
        std::array<std::uint16_t, 3>& last = lastValues_.last[values];
        if (rgb_.changes) {
            last = decodeRgb(rgb_.decoder, models_[lastValues_.current], last);
        }
        for (int i = 0; i < 3; ++i) {
            store(item + 2 * i, last[i]);
        }
    }

  protected:
    static std::array<std::uint16_t, 3> loadRgb(const std::byte* item) {
        return {loadLittleEndian<std::uint16_t>(item), loadLittleEndian<std::uint16_t>(item + 2),
                loadLittleEndian<std::uint16_t>(item + 4)};
    }

  private:
    Layer rgb_;
    ChannelLastValues<std::array<std::uint16_t, 3>> lastValues_;
    std::array<RgbModels, kChannels> models_;
};

class RgbNir14Decoder final : public LayeredItemDecoder {
  public:
    std::size_t layerCount() const override { return 2; }

    void start(const std::byte* item, std::span<const std::span<const std::byte>> layers,
               std::uint32_t& context) override {
        rgb_.start(layers[0]);
        nir_.start(layers[1]);
        lastValues_.start(
            {loadLittleEndian<std::uint16_t>(item), loadLittleEndian<std::uint16_t>(item + 2),
             loadLittleEndian<std::uint16_t>(item + 4), loadLittleEndian<std::uint16_t>(item + 6)},
            context);
        models_[context].reset();
    }

    void decode(std::byte* item, std::uint32_t& context) override {
        bool fresh = false;
        const std::uint32_t values = lastValues_.follow(context, fresh);
        Models& models = models_[lastValues_.current];
        if (fresh) {
            models.reset();
        }
        std::array<std::uint16_t, 4>& last = lastValues_.last[values];
        if (rgb_.changes) {
            const std::array<std::uint16_t, 3> rgb =
                decodeRgb(rgb_.decoder, models.rgb, {last[0], last[1], last[2]});
            last = {rgb[0], rgb[1], rgb[2], last[3]};
        }
        if (nir_.changes) {
            const std::uint32_t changed = nir_.decoder.decodeSymbol(models.nirChangedBytes);
            std::int32_t low = last[3] & 0xFF;
            std::int32_t high = last[3] >> 8;
            if (changed & 1) {
                low = foldByte(
                    static_cast<std::int32_t>(nir_.decoder.decodeSymbol(models.nirDifferences[0])) +
                    low);
            }
            if (changed & 2) {
                high = foldByte(
                    static_cast<std::int32_t>(nir_.decoder.decodeSymbol(models.nirDifferences[1])) +
                    high);
            }
            last[3] = static_cast<std::uint16_t>(low | (high << 8));
        }
        for (int i = 0; i < 4; ++i) {
            store(item + 2 * i, last[i]);
        }
    }

  private:
    struct Models {
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

    Layer rgb_;
    Layer nir_;
    ChannelLastValues<std::array<std::uint16_t, 4>> lastValues_;
    std::array<Models, kChannels> models_;
};

/// Extra bytes: one layer per byte, each byte the last one plus an adaptive difference.
class Byte14Decoder final : public LayeredItemDecoder {
  public:
    explicit Byte14Decoder(std::size_t count)
        : count_(count), layers_(count), models_(kChannels * count, SymbolModel(256)) {}

    std::size_t layerCount() const override { return count_; }

    void start(const std::byte* item, std::span<const std::span<const std::byte>> layers,
               std::uint32_t& context) override {
        for (std::size_t i = 0; i < count_; ++i) {
            layers_[i].start(layers[i]);
        }
        std::vector<std::uint8_t> first(count_);
        std::memcpy(first.data(), item, count_);
        lastValues_.start(first, context);
        resetModels(context);
    }

    void decode(std::byte* item, std::uint32_t& context) override {
        bool fresh = false;
        const std::uint32_t values = lastValues_.follow(context, fresh);
        if (fresh) {
            resetModels(lastValues_.current);
        }
        std::vector<std::uint8_t>& last = lastValues_.last[values];
        for (std::size_t i = 0; i < count_; ++i) {
            if (layers_[i].changes) {
                last[i] =
                    foldByte(last[i] + static_cast<std::int32_t>(layers_[i].decoder.decodeSymbol(
                                           models_[lastValues_.current * count_ + i])));
            }
        }
        std::memcpy(item, last.data(), count_);
    }

  private:
    void resetModels(std::uint32_t channel) {
        for (std::size_t i = 0; i < count_; ++i) {
            models_[channel * count_ + i].reset();
        }
    }

    std::size_t count_;
    std::vector<Layer> layers_;
    std::vector<SymbolModel> models_;  // channel-major
    ChannelLastValues<std::vector<std::uint8_t>> lastValues_;
};

}  // namespace

std::unique_ptr<LayeredItemDecoder> makeLayeredItemDecoder(const ItemSpec& item) {
    switch (item.type) {
        case ItemType::Point14:
            return std::make_unique<Point14Decoder>();
        case ItemType::Rgb14:
            return std::make_unique<Rgb14Decoder>();
        case ItemType::RgbNir14:
            return std::make_unique<RgbNir14Decoder>();
        case ItemType::Byte14:
            return std::make_unique<Byte14Decoder>(item.size);
        default:
            throw Error(fmt::format(
                "the LAZ item type {} is not supported in layered chunks (supported: POINT14, "
                "RGB14, RGBNIR14 and BYTE14; wave packets are not)",
                static_cast<int>(item.type)));
    }
}

}  // namespace subscan::laz
