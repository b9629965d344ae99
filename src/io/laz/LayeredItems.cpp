// LASzip's version 3 item decoders (layered chunks of LAS 1.4 points), written from Isenburg's
// LAS 1.4 compression design and the behaviour of the reference decoder: POINT14, RGB14,
// RGBNIR14 and BYTE14. Each field group has its own layer, and each of the four scanner
// channels its own models and last values (LayeredCoding.h).
#include <array>
#include <cstring>
#include <optional>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/laz/IntegerDecompressor.h"
#include "io/laz/ItemCoding.h"
#include "io/laz/LayeredCoding.h"
#include "io/laz/LazItems.h"

namespace subscan::laz {

namespace {

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

using Point14DecodingState = Point14ChannelState<IntegerDecompressor, GpsTimeDecoder>;

class Point14Decoder final : public LayeredItemDecoder {
  public:
    std::size_t layerCount() const override { return kPoint14Layers; }

    void start(const std::byte* item, std::span<const std::span<const std::byte>> layers,
               std::uint32_t& context) override {
        for (std::size_t i = 0; i < kPoint14Layers; ++i) {
            layers_[i].start(layers[i]);
        }
        channels_.start(Point14::load(item));
        context = channels_.currentChannel();
    }

    void decode(std::byte* item, std::uint32_t& context) override {
        ArithmeticDecoder& xy = layers_[kChannelReturnsXY].decoder;
        if (!layers_[kChannelReturnsXY].changes) {
            throw Error("the LAZ chunk has more than one point but no coordinate layer");
        }
        Point14DecodingState* state = &channels_.current();
        Point14* last = &state->last;

        const std::uint32_t changed = xy.decodeSymbol(state->changedValues[last->changeContext()]);
        namespace change = point14_change;
        if (changed & change::kScannerChannel) {
            const std::uint32_t channel =
                (channels_.currentChannel() + xy.decodeSymbol(state->scannerChannel) + 1) %
                kScannerChannels;
            channels_.switchTo(channel, *last);
            context = channel;
            state = &channels_.current();
            last = &state->last;
            last->scannerChannel = channel;
        }
        const bool pointSourceChanged = changed & change::kPointSource;
        const bool gpsTimeChanged = changed & change::kGpsTime;
        const bool scanAngleChanged = changed & change::kScanAngle;

        const std::uint32_t lastN = last->numberOfReturns;
        const std::uint32_t lastR = last->returnNumber;
        std::uint32_t n = lastN;
        if (changed & change::kNumberOfReturns) {
            n = xy.decodeSymbol(state->numberOfReturns[lastN]);
            last->numberOfReturns = n;
        }
        std::uint32_t r = lastR;
        switch (changed & change::kReturnNumber) {
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
        const std::uint32_t firstLast = last->firstLastContext();

        const std::uint32_t single = n == 1 ? 1 : 0;
        const std::size_t medianIndex = (m << 1) | (gpsTimeChanged ? 1 : 0);
        std::int32_t diff =
            state->dx.decompress(xy, state->xDiffMedians[medianIndex].get(), single);
        last->x = wrappingAdd(last->x, diff);
        state->xDiffMedians[medianIndex].add(diff);
        diff = state->dy.decompress(xy, state->yDiffMedians[medianIndex].get(),
                                    state->yContext(single));
        last->y = wrappingAdd(last->y, diff);
        state->yDiffMedians[medianIndex].add(diff);

        if (layers_[kZ].changes) {
            last->z =
                state->z.decompress(layers_[kZ].decoder, state->lastZ[l], state->zContext(single));
            state->lastZ[l] = last->z;
        }
        if (layers_[kClassification].changes) {
            const std::uint32_t modelIndex =
                ((last->classification & 0x1F) << 1) + (firstLast == 3 ? 1 : 0);
            last->classification =
                layers_[kClassification].decoder.decodeSymbol(state->classifications[modelIndex]);
        }
        if (layers_[kFlags].changes) {
            last->setFlagBits(layers_[kFlags].decoder.decodeSymbol(state->flags[last->flagBits()]));
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
    std::array<Layer, kPoint14Layers> layers_;
    Point14Channels<Point14DecodingState> channels_;
};

class Rgb14Decoder final : public LayeredItemDecoder {
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
            storeLittleEndian(item + 2 * i, last[i]);
        }
    }

  private:
    Layer rgb_;
    ChannelLastValues<std::array<std::uint16_t, 3>> lastValues_;
    std::array<RgbModels, kScannerChannels> models_;
};

class RgbNir14Decoder final : public LayeredItemDecoder {
  public:
    std::size_t layerCount() const override { return 2; }

    void start(const std::byte* item, std::span<const std::span<const std::byte>> layers,
               std::uint32_t& context) override {
        rgb_.start(layers[0]);
        nir_.start(layers[1]);
        lastValues_.start(loadRgbNir(item), context);
        models_[context].reset();
    }

    void decode(std::byte* item, std::uint32_t& context) override {
        bool fresh = false;
        const std::uint32_t values = lastValues_.follow(context, fresh);
        RgbNirModels& models = models_[lastValues_.current];
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
            storeLittleEndian(item + 2 * i, last[i]);
        }
    }

  private:
    Layer rgb_;
    Layer nir_;
    ChannelLastValues<std::array<std::uint16_t, 4>> lastValues_;
    std::array<RgbNirModels, kScannerChannels> models_;
};

/// Extra bytes: one layer per byte, each byte the last one plus an adaptive difference.
class Byte14Decoder final : public LayeredItemDecoder {
  public:
    explicit Byte14Decoder(std::size_t count) : count_(count), layers_(count), models_(count) {}

    std::size_t layerCount() const override { return count_; }

    void start(const std::byte* item, std::span<const std::span<const std::byte>> layers,
               std::uint32_t& context) override {
        for (std::size_t i = 0; i < count_; ++i) {
            layers_[i].start(layers[i]);
        }
        std::vector<std::uint8_t> first(count_);
        std::memcpy(first.data(), item, count_);
        lastValues_.start(first, context);
        models_.reset(context);
    }

    void decode(std::byte* item, std::uint32_t& context) override {
        bool fresh = false;
        const std::uint32_t values = lastValues_.follow(context, fresh);
        if (fresh) {
            models_.reset(lastValues_.current);
        }
        std::vector<std::uint8_t>& last = lastValues_.last[values];
        for (std::size_t i = 0; i < count_; ++i) {
            if (layers_[i].changes) {
                last[i] =
                    foldByte(last[i] + static_cast<std::int32_t>(layers_[i].decoder.decodeSymbol(
                                           models_.of(lastValues_.current, i))));
            }
        }
        std::memcpy(item, last.data(), count_);
    }

  private:
    std::size_t count_;
    std::vector<Layer> layers_;
    Byte14Models models_;
    ChannelLastValues<std::vector<std::uint8_t>> lastValues_;
};

}  // namespace

std::unique_ptr<LayeredItemDecoder> makeLayeredItemDecoder(const ItemSpec& item) {
    std::unique_ptr<LayeredItemDecoder> decoder =
        makeLayeredItemCoder<LayeredItemDecoder, Point14Decoder, Rgb14Decoder, RgbNir14Decoder,
                             Byte14Decoder>(item);
    if (!decoder) {
        throw Error(fmt::format(
            "the LAZ item type {} is not supported in layered chunks (supported: POINT14, "
            "RGB14, RGBNIR14 and BYTE14; wave packets are not)",
            static_cast<int>(item.type)));
    }
    return decoder;
}

}  // namespace subscan::laz
