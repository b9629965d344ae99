// LASzip's version 2 item coders (pointwise chunks), written from Isenburg 2013 and the
// behaviour of the reference decoder: POINT10, GPSTIME11, RGB12 and BYTE.
#include <array>
#include <cstring>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/laz/IntegerDecompressor.h"
#include "io/laz/ItemCoding.h"
#include "io/laz/LazItems.h"

namespace subscan::laz {

namespace {

template <class T>
void store(std::byte* p, T value) {
    std::memcpy(p, &value, sizeof(T));  // little-endian hosts only (checked in LazDecoder)
}

// Contexts by return: which of the 16 (number of returns, return number) classes a pulse's
// return falls in, and how far it is from the last return (LASzip's tables for 3-bit fields).
constexpr std::uint8_t kReturnMap[8][8] = {
    {15, 14, 13, 12, 11, 10, 9, 8},  {14, 0, 1, 3, 6, 10, 10, 9},
    {13, 1, 2, 4, 7, 11, 11, 10},    {12, 3, 4, 5, 8, 12, 12, 11},
    {11, 6, 7, 8, 9, 13, 13, 12},    {10, 10, 11, 12, 13, 14, 14, 13},
    {9, 10, 11, 12, 13, 14, 15, 14}, {8, 9, 10, 11, 12, 13, 14, 15}};

std::uint32_t returnLevel(std::uint32_t numberOfReturns, std::uint32_t returnNumber) {
    return numberOfReturns > returnNumber ? numberOfReturns - returnNumber
                                          : returnNumber - numberOfReturns;
}

/// The 20-byte core of point formats 0-5.
class Point10Decoder final : public PointwiseItemDecoder {
  public:
    void start(const std::byte* item) override {
        x_ = loadLittleEndian<std::int32_t>(item);
        y_ = loadLittleEndian<std::int32_t>(item + 4);
        z_ = loadLittleEndian<std::int32_t>(item + 8);
        intensity_ = 0;  // the coder predicts the second point's intensity from 0
        bits_ = static_cast<std::uint8_t>(item[14]);
        classification_ = static_cast<std::uint8_t>(item[15]);
        scanAngleRank_ = static_cast<std::uint8_t>(item[16]);
        userData_ = static_cast<std::uint8_t>(item[17]);
        pointSourceId_ = loadLittleEndian<std::uint16_t>(item + 18);
        for (Median5& median : xDiffMedians_) {
            median.reset();
        }
        for (Median5& median : yDiffMedians_) {
            median.reset();
        }
        lastIntensities_ = {};
        lastHeights_ = {};
        changedValues_.reset();
        intensities_.reset();
        scanAngleRanks_[0].reset();
        scanAngleRanks_[1].reset();
        pointSourceIds_.reset();
        bitBytes_.reset();
        classifications_.reset();
        userDataModels_.reset();
        dx_.reset();
        dy_.reset();
        dz_.reset();
    }

    void decode(ArithmeticDecoder& decoder, std::byte* item) override {
        const std::uint32_t changed = decoder.decodeSymbol(changedValues_);
        if (changed & 32) {
            bits_ = static_cast<std::uint8_t>(decoder.decodeSymbol(bitBytes_[bits_]));
        }
        const std::uint32_t returnNumber = bits_ & 7;
        const std::uint32_t numberOfReturns = (bits_ >> 3) & 7;
        const std::uint32_t m = kReturnMap[numberOfReturns][returnNumber];
        const std::uint32_t l = returnLevel(numberOfReturns, returnNumber);
        if (changed != 0) {
            if (changed & 16) {
                intensity_ = static_cast<std::uint16_t>(
                    intensities_.decompress(decoder, lastIntensities_[m], m < 3 ? m : 3));
                lastIntensities_[m] = intensity_;
            } else {
                intensity_ = lastIntensities_[m];
            }
            if (changed & 8) {
                classification_ = static_cast<std::uint8_t>(
                    decoder.decodeSymbol(classifications_[classification_]));
            }
            if (changed & 4) {
                const std::uint32_t scanDirection = (bits_ >> 6) & 1;
                scanAngleRank_ = foldByte(static_cast<std::int32_t>(decoder.decodeSymbol(
                                              scanAngleRanks_[scanDirection])) +
                                          scanAngleRank_);
            }
            if (changed & 2) {
                userData_ =
                    static_cast<std::uint8_t>(decoder.decodeSymbol(userDataModels_[userData_]));
            }
            if (changed & 1) {
                pointSourceId_ =
                    static_cast<std::uint16_t>(pointSourceIds_.decompress(decoder, pointSourceId_));
            }
        }

        const std::uint32_t single = numberOfReturns == 1 ? 1 : 0;
        std::int32_t diff = dx_.decompress(decoder, xDiffMedians_[m].get(), single);
        x_ = wrappingAdd(x_, diff);
        xDiffMedians_[m].add(diff);
        std::uint32_t k = dx_.lastK();
        diff = dy_.decompress(decoder, yDiffMedians_[m].get(), single + (k < 20 ? k & ~1u : 20));
        y_ = wrappingAdd(y_, diff);
        yDiffMedians_[m].add(diff);
        k = (dx_.lastK() + dy_.lastK()) / 2;
        z_ = dz_.decompress(decoder, lastHeights_[l], single + (k < 18 ? k & ~1u : 18));
        lastHeights_[l] = z_;

        store(item, x_);
        store(item + 4, y_);
        store(item + 8, z_);
        store(item + 12, intensity_);
        store(item + 14, bits_);
        store(item + 15, classification_);
        store(item + 16, scanAngleRank_);
        store(item + 17, userData_);
        store(item + 18, pointSourceId_);
    }

  private:
    std::int32_t x_ = 0, y_ = 0, z_ = 0;
    std::uint16_t intensity_ = 0;
    std::uint8_t bits_ = 0;  // return number, number of returns, scan direction, edge
    std::uint8_t classification_ = 0;
    std::uint8_t scanAngleRank_ = 0;
    std::uint8_t userData_ = 0;
    std::uint16_t pointSourceId_ = 0;

    std::array<Median5, 16> xDiffMedians_{};
    std::array<Median5, 16> yDiffMedians_{};
    std::array<std::uint16_t, 16> lastIntensities_{};
    std::array<std::int32_t, 8> lastHeights_{};

    SymbolModel changedValues_{64};
    IntegerDecompressor intensities_{16, 4};
    std::array<SymbolModel, 2> scanAngleRanks_{SymbolModel(256), SymbolModel(256)};
    IntegerDecompressor pointSourceIds_{16, 1};
    LazySymbolModels bitBytes_{256, 256};
    LazySymbolModels classifications_{256, 256};
    LazySymbolModels userDataModels_{256, 256};
    IntegerDecompressor dx_{32, 2};
    IntegerDecompressor dy_{32, 22};
    IntegerDecompressor dz_{32, 20};
};

class GpsTime11Decoder final : public PointwiseItemDecoder {
  public:
    void start(const std::byte* item) override {
        gpsTime_.reset(loadLittleEndian<std::uint64_t>(item));
    }
    void decode(ArithmeticDecoder& decoder, std::byte* item) override {
        gpsTime_.decode(decoder);
        store(item, gpsTime_.timeBits());
    }

  private:
    GpsTimeDecoder gpsTime_{true};
};

class Rgb12Decoder final : public PointwiseItemDecoder {
  public:
    void start(const std::byte* item) override {
        for (int i = 0; i < 3; ++i) {
            last_[i] = loadLittleEndian<std::uint16_t>(item + 2 * i);
        }
        models_.reset();
    }
    void decode(ArithmeticDecoder& decoder, std::byte* item) override {
        last_ = decodeRgb(decoder, models_, last_);
        for (int i = 0; i < 3; ++i) {
            store(item + 2 * i, last_[i]);
        }
    }

  private:
    std::array<std::uint16_t, 3> last_{};
    RgbModels models_;
};

/// Extra bytes: each byte is the last one plus an adaptive difference.
class ByteDecoder final : public PointwiseItemDecoder {
  public:
    explicit ByteDecoder(std::size_t count) : last_(count), models_(count, SymbolModel(256)) {}
    void start(const std::byte* item) override {
        std::memcpy(last_.data(), item, last_.size());
        for (SymbolModel& model : models_) {
            model.reset();
        }
    }
    void decode(ArithmeticDecoder& decoder, std::byte* item) override {
        for (std::size_t i = 0; i < last_.size(); ++i) {
            last_[i] =
                foldByte(last_[i] + static_cast<std::int32_t>(decoder.decodeSymbol(models_[i])));
        }
        std::memcpy(item, last_.data(), last_.size());
    }

  private:
    std::vector<std::uint8_t> last_;
    std::vector<SymbolModel> models_;
};

}  // namespace

std::unique_ptr<PointwiseItemDecoder> makePointwiseItemDecoder(const ItemSpec& item) {
    switch (item.type) {
        case ItemType::Point10:
            return std::make_unique<Point10Decoder>();
        case ItemType::GpsTime11:
            return std::make_unique<GpsTime11Decoder>();
        case ItemType::Rgb12:
            return std::make_unique<Rgb12Decoder>();
        case ItemType::Byte:
            return std::make_unique<ByteDecoder>(item.size);
        default:
            throw Error(fmt::format(
                "the LAZ item type {} is not supported in pointwise chunks (supported: POINT10, "
                "GPSTIME11, RGB12 and BYTE; wave packets are not)",
                static_cast<int>(item.type)));
    }
}

}  // namespace subscan::laz
