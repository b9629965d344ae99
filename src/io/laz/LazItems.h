#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "io/laz/ArithmeticDecoder.h"

namespace subscan::laz {

/// Item types of the laszip VLR (LASzip's LASitem::Type).
enum class ItemType : std::uint16_t {
    Byte = 0,
    Point10 = 6,
    GpsTime11 = 7,
    Rgb12 = 8,
    WavePacket13 = 9,
    Point14 = 10,
    Rgb14 = 11,
    RgbNir14 = 12,
    WavePacket14 = 13,
    Byte14 = 14,
};

struct ItemSpec {
    ItemType type;
    std::uint16_t size;     // bytes of the item in the point record
    std::uint16_t version;  // coder generation: 2 (pointwise) or 3 (layered)
};

/// Decoder of one item of a pointwise-chunked point (compressor 2, item version 2): all items
/// share one arithmetic stream, item after item, point after point.
class PointwiseItemDecoder {
  public:
    virtual ~PointwiseItemDecoder() = default;
    /// Starts a chunk from its first point, stored raw.
    virtual void start(const std::byte* item) = 0;
    virtual void decode(ArithmeticDecoder& decoder, std::byte* item) = 0;
};

/// Decoder of one item of a layered-chunked point (compressor 3, item version 3): each item has
/// one or more layers, separate arithmetic streams whose byte counts precede them in the chunk.
/// The items after POINT14 pick their models by a context that POINT14 sets: to the scanner
/// channel of the chunk's first point, and of each point whose channel differs from the last
/// one's; every other point is coded in context 0. (LASzip's reader and writer start every point
/// from context 0; laz-perf does the same. Items of a chunk on one channel other than 0 thus
/// switch to context 0 at its second point.)
class LayeredItemDecoder {
  public:
    virtual ~LayeredItemDecoder() = default;
    virtual std::size_t layerCount() const = 0;
    /// Starts a chunk: the first point raw, then the item's layers (empty ones leave the field as
    /// in the first point for the whole chunk). `context`: see above.
    virtual void start(const std::byte* item, std::span<const std::span<const std::byte>> layers,
                       std::uint32_t& context) = 0;
    virtual void decode(std::byte* item, std::uint32_t& context) = 0;
};

/// Encoder of one item of a layered-chunked point, the mirror of the LayeredItemDecoder.
class LayeredItemEncoder {
  public:
    virtual ~LayeredItemEncoder() = default;
    virtual std::size_t layerCount() const = 0;
    /// Starts a chunk from its first point (which the chunk stores raw). `context`: as the
    /// decoder's.
    virtual void start(const std::byte* item, std::uint32_t& context) = 0;
    virtual void encode(const std::byte* item, std::uint32_t& context) = 0;
    /// Ends the chunk: appends the item's layers to `layers`, each empty where its fields kept
    /// the first point's values throughout (the decoder then keeps them).
    virtual void finish(std::vector<std::vector<std::byte>>& layers) = 0;
};

std::unique_ptr<PointwiseItemDecoder> makePointwiseItemDecoder(const ItemSpec& item);
std::unique_ptr<LayeredItemDecoder> makeLayeredItemDecoder(const ItemSpec& item);
/// POINT14, RGB14, RGBNIR14 or BYTE14 (version 3); throws subscan::Error for other items.
std::unique_ptr<LayeredItemEncoder> makeLayeredItemEncoder(const ItemSpec& item);

}  // namespace subscan::laz
