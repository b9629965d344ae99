// LASzip's version 3 item encoders (layered chunks of LAS 1.4 points), the mirrors of the
// decoders in LayeredItems.cpp: POINT14, RGB14, RGBNIR14 and BYTE14. Where the format leaves the
// encoder a choice, they choose as LASzip's writer does (see each choice), so that a chunk
// LASzip (or laz-perf) wrote re-encodes to the same bytes.
#include <algorithm>
#include <array>
#include <cstring>
#include <optional>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/laz/IntegerCompressor.h"
#include "io/laz/ItemEncoding.h"
#include "io/laz/LayeredCoding.h"
#include "io/laz/LazItems.h"

namespace subscan::laz {

namespace {

/// A layer's stream, and whether the fields it codes changed within the chunk.
struct EncoderLayer {
    ArithmeticEncoder encoder;
    bool changed = false;

    /// The layer's bytes; none where nothing changed, unless `always` (LASzip always writes
    /// POINT14's first two layers, even for a chunk of one point).
    std::vector<std::byte> finish(bool always) {
        std::vector<std::byte> bytes = encoder.finish();
        if (!changed && !always) {
            bytes.clear();
        }
        changed = false;
        return bytes;
    }
};

using Point14EncodingState = Point14ChannelState<IntegerCompressor, GpsTimeEncoder>;

/// The return number's part of the change mask: 0 same, 1 one up, 2 one down (modulo 16), 3
/// any other (coded separately).
std::uint32_t returnNumberChange(std::uint32_t last, std::uint32_t now) {
    if (now == last) {
        return 0;
    }
    if (now == (last + 1) % 16) {
        return 1;
    }
    return now == (last + 15) % 16 ? 2 : 3;
}

std::int32_t wrappingSubtract(std::int32_t a, std::int32_t b) {
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) - static_cast<std::uint32_t>(b));
}

class Point14Encoder final : public LayeredItemEncoder {
  public:
    std::size_t layerCount() const override { return kPoint14Layers; }

    void start(const std::byte* item, std::uint32_t& context) override {
        layers_ = {};
        channels_.start(Point14::load(item));
        context = channels_.currentChannel();
    }

    void encode(const std::byte* item, std::uint32_t& context) override {
        namespace change = point14_change;
        const Point14 point = Point14::load(item);
        Point14EncodingState* state = &channels_.current();
        ArithmeticEncoder& xy = layers_[kChannelReturnsXY].encoder;

        // Fields compare with the last point of the point's own channel where that channel
        // already occurred in the chunk, else with the last point (a new channel starts there).
        const std::uint32_t channel = point.scannerChannel;
        const std::uint32_t current = channels_.currentChannel();
        const bool switches = channel != current;
        const Point14& reference =
            switches && channels_.seen(channel) ? channels_[channel].last : state->last;
        // Times compare by their bits (LASzip compares the doubles): a time of -0.0 after 0.0
        // stays -0.0, and equal NaNs are no change.
        const bool gpsTimeChanged = point.gpsTimeBits != reference.gpsTimeBits;
        const bool scanAngleChanged = point.scanAngle != reference.scanAngle;
        const bool pointSourceChanged = point.pointSourceId != reference.pointSourceId;
        const std::uint32_t lastN = reference.numberOfReturns;
        const std::uint32_t lastR = reference.returnNumber;
        const std::uint32_t n = point.numberOfReturns;
        const std::uint32_t r = point.returnNumber;
        std::uint32_t changed = returnNumberChange(lastR, r);
        changed |= n != lastN ? change::kNumberOfReturns : 0;
        changed |= scanAngleChanged ? change::kScanAngle : 0;
        changed |= gpsTimeChanged ? change::kGpsTime : 0;
        changed |= pointSourceChanged ? change::kPointSource : 0;
        changed |= switches ? change::kScannerChannel : 0;
        xy.encodeSymbol(state->changedValues[state->last.changeContext()], changed);

        if (switches) {
            // The new channel as a step of 1 to 3 from the current one.
            xy.encodeSymbol(state->scannerChannel,
                            (channel + kScannerChannels - current - 1) % kScannerChannels);
            channels_.switchTo(channel, state->last);
            context = channel;
            state = &channels_.current();
        }
        Point14& last = state->last;  // holds the values of `reference` now

        if (n != lastN) {
            xy.encodeSymbol(state->numberOfReturns[lastN], n);
        }
        if ((changed & change::kReturnNumber) == change::kReturnNumber) {
            if (gpsTimeChanged) {
                xy.encodeSymbol(state->returnNumber[lastR], r);
            } else {
                xy.encodeSymbol(state->returnNumberGpsSame, (r + 16 - lastR) % 16 - 2);
            }
        }

        const std::uint32_t l = returnLevel8(n, r);
        const std::uint32_t firstLast = point.firstLastContext();
        const bool single = n == 1;
        const std::size_t medianIndex = (kReturnMap6[n][r] << 1) | (gpsTimeChanged ? 1 : 0);
        std::int32_t diff = wrappingSubtract(point.x, last.x);
        state->dx.compress(xy, state->xDiffMedians[medianIndex].get(), diff, single ? 1 : 0);
        state->xDiffMedians[medianIndex].add(diff);
        diff = wrappingSubtract(point.y, last.y);
        state->dy.compress(xy, state->yDiffMedians[medianIndex].get(), diff,
                           state->yContext(single));
        state->yDiffMedians[medianIndex].add(diff);

        state->z.compress(layers_[kZ].encoder, state->lastZ[l], point.z, state->zContext(single));
        state->lastZ[l] = point.z;

        EncoderLayer& classes = layers_[kClassification];
        const std::uint32_t classModel =
            ((last.classification & 0x1F) << 1) + (firstLast == 3 ? 1 : 0);
        classes.encoder.encodeSymbol(state->classifications[classModel], point.classification);
        classes.changed |= point.classification != last.classification;

        EncoderLayer& flags = layers_[kFlags];
        flags.encoder.encodeSymbol(state->flags[last.flagBits()], point.flagBits());
        flags.changed |= point.flagBits() != last.flagBits();

        EncoderLayer& intensity = layers_[kIntensity];
        const std::size_t slot = (firstLast << 1) | (gpsTimeChanged ? 1 : 0);
        state->intensity.compress(intensity.encoder, state->lastIntensities[slot], point.intensity,
                                  firstLast);
        state->lastIntensities[slot] = point.intensity;
        intensity.changed |= point.intensity != last.intensity;

        if (scanAngleChanged) {
            state->scanAngle.compress(layers_[kScanAngle].encoder, last.scanAngle, point.scanAngle,
                                      gpsTimeChanged ? 1 : 0);
            layers_[kScanAngle].changed = true;
        }

        EncoderLayer& userData = layers_[kUserData];
        userData.encoder.encodeSymbol(state->userData[last.userData / 4], point.userData);
        userData.changed |= point.userData != last.userData;

        if (pointSourceChanged) {
            state->pointSource.compress(layers_[kPointSource].encoder, last.pointSourceId,
                                        point.pointSourceId);
            layers_[kPointSource].changed = true;
        }
        if (gpsTimeChanged) {
            state->gpsTime.encode(layers_[kGpsTime].encoder, point.gpsTimeBits);
            layers_[kGpsTime].changed = true;
        }
        last = point;
        last.gpsTimeChanged = gpsTimeChanged;
    }

    void finish(std::vector<std::vector<std::byte>>& layers) override {
        for (std::size_t i = 0; i < kPoint14Layers; ++i) {
            layers.push_back(layers_[i].finish(i == kChannelReturnsXY || i == kZ));
        }
    }

  private:
    std::array<EncoderLayer, kPoint14Layers> layers_;
    Point14Channels<Point14EncodingState> channels_;
};

class Rgb14Encoder final : public LayeredItemEncoder {
  public:
    std::size_t layerCount() const override { return 1; }

    void start(const std::byte* item, std::uint32_t& context) override {
        rgb_ = {};
        lastValues_.start(loadRgb(item), context);
        models_[context].reset();
    }

    void encode(const std::byte* item, std::uint32_t& context) override {
        bool fresh = false;
        const std::uint32_t values = lastValues_.follow(context, fresh);
        RgbModels& models = models_[lastValues_.current];
        if (fresh) {
            models.reset();
        }
        std::array<std::uint16_t, 3>& last = lastValues_.last[values];
        const std::array<std::uint16_t, 3> now = loadRgb(item);
        rgb_.changed |= encodeRgb(rgb_.encoder, models, last, now) != 0;
        last = now;
    }

    void finish(std::vector<std::vector<std::byte>>& layers) override {
        layers.push_back(rgb_.finish(false));
    }

  private:
    EncoderLayer rgb_;
    ChannelLastValues<std::array<std::uint16_t, 3>> lastValues_;
    std::array<RgbModels, kScannerChannels> models_;
};

class RgbNir14Encoder final : public LayeredItemEncoder {
  public:
    std::size_t layerCount() const override { return 2; }

    void start(const std::byte* item, std::uint32_t& context) override {
        rgb_ = {};
        nir_ = {};
        lastValues_.start(loadRgbNir(item), context);
        models_[context].reset();
    }

    void encode(const std::byte* item, std::uint32_t& context) override {
        bool fresh = false;
        const std::uint32_t values = lastValues_.follow(context, fresh);
        RgbNirModels& models = models_[lastValues_.current];
        if (fresh) {
            models.reset();
        }
        std::array<std::uint16_t, 4>& last = lastValues_.last[values];
        const std::array<std::uint16_t, 4> now = loadRgbNir(item);
        rgb_.changed |= encodeRgb(rgb_.encoder, models.rgb, {last[0], last[1], last[2]},
                                  {now[0], now[1], now[2]}) != 0;

        const std::int32_t lowNow = now[3] & 0xFF;
        const std::int32_t lowLast = last[3] & 0xFF;
        const std::int32_t highNow = now[3] >> 8;
        const std::int32_t highLast = last[3] >> 8;
        const std::uint32_t changedBytes =
            (lowNow != lowLast ? 1u : 0u) | (highNow != highLast ? 2u : 0u);
        nir_.encoder.encodeSymbol(models.nirChangedBytes, changedBytes);
        if (changedBytes & 1) {
            nir_.encoder.encodeSymbol(models.nirDifferences[0], foldByte(lowNow - lowLast));
        }
        if (changedBytes & 2) {
            nir_.encoder.encodeSymbol(models.nirDifferences[1], foldByte(highNow - highLast));
        }
        nir_.changed |= changedBytes != 0;
        last = now;
    }

    void finish(std::vector<std::vector<std::byte>>& layers) override {
        layers.push_back(rgb_.finish(false));
        layers.push_back(nir_.finish(false));
    }

  private:
    EncoderLayer rgb_;
    EncoderLayer nir_;
    ChannelLastValues<std::array<std::uint16_t, 4>> lastValues_;
    std::array<RgbNirModels, kScannerChannels> models_;
};

/// Extra bytes: one layer per byte, each byte coded as its difference to the last one.
class Byte14Encoder final : public LayeredItemEncoder {
  public:
    explicit Byte14Encoder(std::size_t count) : count_(count), layers_(count), models_(count) {}

    std::size_t layerCount() const override { return count_; }

    void start(const std::byte* item, std::uint32_t& context) override {
        std::fill(layers_.begin(), layers_.end(), EncoderLayer{});
        std::vector<std::uint8_t> first(count_);
        std::memcpy(first.data(), item, count_);
        lastValues_.start(first, context);
        models_.reset(context);
    }

    void encode(const std::byte* item, std::uint32_t& context) override {
        bool fresh = false;
        const std::uint32_t values = lastValues_.follow(context, fresh);
        if (fresh) {
            models_.reset(lastValues_.current);
        }
        std::vector<std::uint8_t>& last = lastValues_.last[values];
        for (std::size_t i = 0; i < count_; ++i) {
            const auto now = static_cast<std::uint8_t>(item[i]);
            const std::uint8_t difference = foldByte(now - last[i]);
            layers_[i].encoder.encodeSymbol(models_.of(lastValues_.current, i), difference);
            layers_[i].changed |= difference != 0;
            last[i] = now;
        }
    }

    void finish(std::vector<std::vector<std::byte>>& layers) override {
        for (EncoderLayer& layer : layers_) {
            layers.push_back(layer.finish(false));
        }
    }

  private:
    std::size_t count_;
    std::vector<EncoderLayer> layers_;
    Byte14Models models_;
    ChannelLastValues<std::vector<std::uint8_t>> lastValues_;
};

}  // namespace

std::unique_ptr<LayeredItemEncoder> makeLayeredItemEncoder(const ItemSpec& item) {
    std::unique_ptr<LayeredItemEncoder> encoder =
        makeLayeredItemCoder<LayeredItemEncoder, Point14Encoder, Rgb14Encoder, RgbNir14Encoder,
                             Byte14Encoder>(item);
    if (!encoder) {
        throw Error(fmt::format(
            "the LAZ encoder writes POINT14, RGB14, RGBNIR14 and BYTE14 items, not item type {}",
            static_cast<int>(item.type)));
    }
    return encoder;
}

}  // namespace subscan::laz
