#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/InputFile.h"
#include "io/LasFormat.h"
#include "io/LasHeader.h"
#include "io/LazChunkStream.h"
#include "io/RecordSourceSupport.h"
#include "io/laz/LazDecoder.h"

// LAS and LAZ files as LAS 1.4 records of format 6, 7 or 8, read in pieces: the header and VLRs
// once, then the point data a block (LAS) or a chunk (LAZ) at a time.
namespace subscan {

namespace {

/// Records read from an uncompressed file at once: 64 Ki records, at most 4 MiB of a format 10
/// file with extra bytes; large enough that the calls cost nothing next to the copying.
constexpr std::size_t kRecordsPerBlock = 1 << 16;

constexpr std::string_view kProjectionUser = "LASF_Projection";
constexpr std::uint16_t kWktRecord = 2112;
constexpr std::uint16_t kGeoKeysRecord = 34735;
constexpr std::string_view kSpecUser = "LASF_Spec";
constexpr std::uint16_t kExtraBytesRecord = 4;

/// The header and VLRs are read into memory; real ones take kilobytes (a VLR holds at most 64 KiB),
/// so a point data offset beyond this is a corrupt header, not a reason to allocate gigabytes.
constexpr std::uint32_t kLargestHead = 256u << 20;
/// WKT and extra-bytes descriptors are a few kilobytes; a larger payload is something else.
constexpr std::uint64_t kLargestEvlrRead = 16u << 20;

// The legacy point core of formats 0-5 (R15, table 7), where it differs from the 1.4 core.
constexpr std::size_t kLegacyReturns = 14;         // return (0-2), returns (3-5), direction, edge
constexpr std::size_t kLegacyClassification = 15;  // class (0-4), synthetic, key-point, withheld
constexpr std::size_t kLegacyScanAngleRank = 16;   // int8 degrees
constexpr std::size_t kLegacyUserData = 17;
constexpr std::size_t kLegacyPointSourceId = 18;
constexpr std::size_t kLegacyGpsTime = 20;  // formats 1, 3, 4 and 5
constexpr std::size_t kScanAngleRankSteps = 256;

/// The payload of the first extended VLR (LAS 1.4, after the point data) with this user id and
/// record id. Like the VLR search, a malformed record ends the search rather than the read.
std::optional<std::vector<std::byte>> findEvlr(const InputFile& file, const LasHeader& header,
                                               std::string_view user, std::uint16_t recordId) {
    std::uint64_t position = header.evlrOffset;
    for (std::uint32_t i = 0; i < header.evlrCount; ++i) {
        if (position < header.pointDataOffset || position > file.size() ||
            file.size() - position < las::kEvlrHeaderSize) {
            return std::nullopt;
        }
        const std::vector<std::byte> record = file.read(position, las::kEvlrHeaderSize);
        const std::string_view userId(
            reinterpret_cast<const char*>(record.data() + las::kVlrUserIdOffset),
            las::kVlrUserIdSize);
        const auto length = loadLittleEndian<std::uint64_t>(record.data() + las::kVlrLengthOffset);
        if (length > file.size() - position - las::kEvlrHeaderSize) {
            return std::nullopt;
        }
        if (userId.substr(0, userId.find('\0')) == user &&
            loadLittleEndian<std::uint16_t>(record.data() + las::kVlrRecordIdOffset) == recordId) {
            if (length > kLargestEvlrRead) {
                return std::nullopt;
            }
            return file.read(position + las::kEvlrHeaderSize, static_cast<std::size_t>(length));
        }
        position += las::kEvlrHeaderSize + length;
    }
    return std::nullopt;
}

/// A VLR's payload, else the EVLR's, copied.
std::optional<std::vector<std::byte>> findRecord(const InputFile& file,
                                                 std::span<const std::byte> head,
                                                 const LasHeader& header, std::string_view user,
                                                 std::uint16_t recordId) {
    if (const auto vlr = findLasVlr(head, header, user, recordId)) {
        return std::vector<std::byte>(vlr->begin(), vlr->end());
    }
    return findEvlr(file, header, user, recordId);
}

/// The WKT text without the NUL padding writers leave after it.
std::string wktText(std::span<const std::byte> payload) {
    std::string text(reinterpret_cast<const char*>(payload.data()), payload.size());
    text.erase(text.find_last_not_of(std::string_view("\0 \t\r\n", 5)) + 1);
    return text;
}

/// Converts records of any LAS point format (0-10) into format 6, 7 or 8 (R15, section 2.6).
class RecordConverter {
  public:
    RecordConverter(int inputFormat, std::size_t inputLength)
        : inputFormat_(inputFormat),
          inputLength_(inputLength),
          inputColor_(kLasPointFormats[inputFormat].colorOffset),
          extraBytes_(inputLength - kLasPointFormats[inputFormat].recordSize) {
        outputFormat_ = inputFormat == 8 || inputFormat == 10 ? 8 : inputColor_ ? 7 : 6;
        outputLength_ = las14::standardSize(outputFormat_) + extraBytes_;
        for (std::size_t rank = 0; rank < kScanAngleRankSteps; ++rank) {
            // int8 whole degrees to int16 steps of 0.006 degrees: |127 / 0.006| < 32767.
            const auto degrees = static_cast<std::int8_t>(rank);
            scanAngles_[rank] = static_cast<std::int16_t>(std::lround(degrees / 0.006));
        }
    }

    int outputFormat() const { return outputFormat_; }
    std::size_t outputLength() const { return outputLength_; }
    std::size_t extraBytes() const { return extraBytes_; }

    void convert(const std::byte* in, std::size_t count, std::byte* out) const {
        if (inputFormat_ >= 6) {
            for (std::size_t i = 0; i < count; ++i) {
                convertExtended(in + i * inputLength_, out + i * outputLength_);
            }
        } else {
            for (std::size_t i = 0; i < count; ++i) {
                convertLegacy(in + i * inputLength_, out + i * outputLength_);
            }
        }
    }

  private:
    /// Formats 6-10 share the 30-byte core; 9 and 10 lose their wave packet descriptor.
    void convertExtended(const std::byte* in, std::byte* out) const {
        const std::size_t core = las14::kRgb;
        std::memcpy(out, in, core);
        if (outputFormat_ == 8) {
            std::memcpy(out + las14::kRgb, in + las14::kRgb, 8);  // RGB and NIR
        } else if (outputFormat_ == 7) {
            std::memcpy(out + las14::kRgb, in + las14::kRgb, 6);
        }
        copyExtraBytes(in, out);
    }

    /// Formats 0-5: the wider 1.4 fields take the legacy values; what 1.4 added (overlap,
    /// scanner channel) is 0, and GPS time 0 where the format has none.
    void convertLegacy(const std::byte* in, std::byte* out) const {
        std::memcpy(out, in, las14::kReturns);  // X, Y, Z and intensity
        const auto returns = std::to_integer<std::uint8_t>(in[kLegacyReturns]);
        const auto classification = std::to_integer<std::uint8_t>(in[kLegacyClassification]);
        const auto returnNumber = static_cast<std::uint8_t>(returns & 0x07);
        const auto numberOfReturns = static_cast<std::uint8_t>((returns >> 3) & 0x07);
        out[las14::kReturns] = static_cast<std::byte>(returnNumber | (numberOfReturns << 4));
        // Synthetic, key-point and withheld move from bits 5-7 of the class byte to bits 0-2;
        // scan direction and edge of flight line keep bits 6 and 7 of their byte.
        out[las14::kFlags] = static_cast<std::byte>((classification >> 5) | (returns & 0xC0));
        out[las14::kClassification] = static_cast<std::byte>(classification & 0x1F);
        out[las14::kUserData] = in[kLegacyUserData];
        const std::int16_t scanAngle =
            scanAngles_[std::to_integer<std::uint8_t>(in[kLegacyScanAngleRank])];
        std::memcpy(out + las14::kScanAngle, &scanAngle, sizeof(scanAngle));
        std::memcpy(out + las14::kPointSourceId, in + kLegacyPointSourceId, 2);
        if (inputFormat_ == 1 || inputFormat_ >= 3) {
            std::memcpy(out + las14::kGpsTime, in + kLegacyGpsTime, 8);
        } else {
            std::memset(out + las14::kGpsTime, 0, 8);
        }
        if (inputColor_) {
            std::memcpy(out + las14::kRgb, in + *inputColor_, 6);
        }
        copyExtraBytes(in, out);
    }

    void copyExtraBytes(const std::byte* in, std::byte* out) const {
        std::memcpy(out + las14::standardSize(outputFormat_),
                    in + kLasPointFormats[inputFormat_].recordSize, extraBytes_);
    }

    int inputFormat_;
    std::size_t inputLength_;
    std::optional<std::size_t> inputColor_;
    std::size_t extraBytes_;
    int outputFormat_ = 6;
    std::size_t outputLength_ = 0;
    std::array<std::int16_t, kScanAngleRankSteps> scanAngles_{};
};

class LasRecordSource final : public PointRecordSource {
  public:
    LasRecordSource(const std::filesystem::path& path, unsigned threads)
        : path_(path), file_(std::in_place, path), fileSize_(file_->size()), threads_(threads) {
        readHead();
        ReadContext context;
        header_ = parseLasHeader(head_, fileSize_, context);
        info_.name = path.string();
        for (const std::string& warning : context.warnings) {
            info_.warnings.push_back(fmt::format("{}: {}", info_.name, warning));
        }
        if (header_.pointCount == 0) {
            throw Error("it holds no points (its LAS header declares 0)");
        }
        converter_.emplace(header_.pointFormat, header_.recordLength);
        if (header_.laszipRecord) {
            layout_ = laz::parseLaszipRecord(*header_.laszipRecord, header_.pointFormat,
                                             header_.recordLength);
            chunks_ = readLazChunkTable(*file_, header_, *layout_);
        } else {
            checkPointData();
        }
        describe();
        // Closed until the first read: a merge of thousands of tiles must not hold thousands of
        // files (or decoding threads) open at once.
        file_.reset();
    }

    const PointRecordSourceInfo& info() const override { return info_; }

    std::size_t read(std::vector<std::byte>& records, std::size_t maxPoints) override {
        try {
            if (nextPoint_ == header_.pointCount) {
                return 0;
            }
            reopen();
            const std::size_t got =
                layout_ ? readCompressed(records, maxPoints) : readPlain(records, maxPoints);
            if (nextPoint_ == header_.pointCount) {
                close();
            }
            return got;
        } catch (const Error& error) {
            throwNamed(info_.name, error);
        }
    }

    void rewind() override {
        nextPoint_ = 0;
        chunk_.clear();
        chunkPoint_ = 0;
        stream_.reset();  // its workers stop; the next read starts a new stream at chunk 0
    }

  private:
    void reopen() {
        if (!file_) {
            file_.emplace(path_);
            if (file_->size() != fileSize_) {
                throw Error(fmt::format(
                    "the file has {} bytes now, but had {} when it was opened: another program "
                    "changed it; open it again once it is complete",
                    file_->size(), fileSize_));
            }
        }
        if (layout_ && !stream_) {
            stream_ = std::make_unique<LazChunkStream>(*file_, *layout_, chunks_, threads_);
        }
    }

    void close() {
        stream_.reset();
        file_.reset();
        chunk_ = {};
    }

    /// The header and the VLRs, up to the point data.
    void readHead() {
        head_.resize(
            static_cast<std::size_t>(std::min<std::uint64_t>(fileSize_, las::kHeaderSize14)));
        file_->read(0, head_);
        if (head_.size() < las::header_field::kPointDataOffset + 4) {
            return;  // parseLasHeader says what is wrong with so short a file
        }
        const auto pointDataOffset =
            loadLittleEndian<std::uint32_t>(head_.data() + las::header_field::kPointDataOffset);
        if (pointDataOffset > kLargestHead && pointDataOffset <= fileSize_) {
            throw Error(fmt::format(
                "the LAS point data offset {} leaves {} MiB of header and VLRs before the points, "
                "more than any real file has (header corrupt?)",
                pointDataOffset, pointDataOffset >> 20));
        }
        if (pointDataOffset > head_.size() && pointDataOffset <= fileSize_) {
            head_.resize(pointDataOffset);
            file_->read(0, head_);
        }
    }

    /// Where the point data ends: at the extended VLRs of a LAS 1.4 file when they follow it.
    std::uint64_t pointDataEnd() const {
        if (header_.evlrCount > 0 && header_.evlrOffset >= header_.pointDataOffset &&
            header_.evlrOffset <= fileSize_) {
            return header_.evlrOffset;
        }
        return fileSize_;
    }

    void checkPointData() const {
        const std::uint64_t available =
            (pointDataEnd() - header_.pointDataOffset) / header_.recordLength;
        if (header_.pointCount > available) {
            throw Error(
                fmt::format("the LAS header declares {} points, but the point data holds only {} "
                            "(file truncated, or the count is wrong)",
                            header_.pointCount, available));
        }
    }

    void describe() {
        info_.pointCount = header_.pointCount;
        info_.format.pointFormat = converter_->outputFormat();
        info_.format.extraBytes = converter_->extraBytes();
        info_.quantization.scale = header_.scale;
        info_.quantization.offset = header_.offset;
        info_.min = header_.declaredBounds.min;
        info_.max = header_.declaredBounds.max;
        const int format = header_.pointFormat;
        // parseLasHeader has checked that the header is whole.
        info_.fileSourceId =
            loadLittleEndian<std::uint16_t>(head_.data() + las::header_field::kFileSourceId);
        if (format == 1 || format >= 3) {
            const auto encoding =
                loadLittleEndian<std::uint16_t>(head_.data() + las::header_field::kGlobalEncoding);
            info_.standardGpsTime = (encoding & las::kStandardGpsTime) != 0;
        }
        if (format == 4 || format == 5 || format >= 9) {
            info_.warnings.push_back(fmt::format(
                "{}: point format {} carries wave packets; their descriptors (which point into "
                "waveform data) are dropped, every other field is kept",
                info_.name, format));
        }
        describeExtraBytes();
        if (const auto wkt = findRecord(*file_, head_, header_, kProjectionUser, kWktRecord)) {
            info_.wkt = wktText(*wkt);
        }
        if (info_.wkt.empty() && findLasVlr(head_, header_, kProjectionUser, kGeoKeysRecord)) {
            info_.warnings.push_back(fmt::format("{}: {}", info_.name, kGeoKeysOnly));
        }
    }

    void describeExtraBytes() {
        const std::size_t extra = info_.format.extraBytes;
        if (extra == 0) {
            return;
        }
        const auto descriptors = findRecord(*file_, head_, header_, kSpecUser, kExtraBytesRecord);
        if (descriptors && describedBytes(*descriptors) == extra) {
            info_.format.extraBytesDescriptors = *descriptors;
            return;
        }
        if (descriptors) {
            info_.warnings.push_back(fmt::format(
                "{}: its extra-bytes VLR does not describe the {} extra bytes of its records; they "
                "are kept as undocumented bytes",
                info_.name, extra));
        }
        info_.format.extraBytesDescriptors = undocumentedDescriptors(extra);
    }

    std::size_t readPlain(std::vector<std::byte>& records, std::size_t maxPoints) {
        const std::size_t count = static_cast<std::size_t>(
            std::min<std::uint64_t>(maxPoints, header_.pointCount - nextPoint_));
        const std::size_t outputLength = converter_->outputLength();
        const std::size_t start = records.size();
        records.resize(start + count * outputLength);
        for (std::size_t done = 0; done < count;) {
            const std::size_t block = std::min(kRecordsPerBlock, count - done);
            chunk_.resize(block * header_.recordLength);
            file_->read(header_.pointDataOffset + (nextPoint_ + done) * header_.recordLength,
                        chunk_);
            converter_->convert(chunk_.data(), block, records.data() + start + done * outputLength);
            done += block;
        }
        nextPoint_ += count;
        return count;
    }

    std::size_t readCompressed(std::vector<std::byte>& records, std::size_t maxPoints) {
        std::size_t done = 0;
        const std::size_t outputLength = converter_->outputLength();
        while (done < maxPoints) {
            const std::size_t inChunk = chunk_.size() / header_.recordLength - chunkPoint_;
            if (inChunk == 0) {
                chunkPoint_ = 0;
                if (!stream_->next(chunk_)) {
                    break;
                }
                continue;
            }
            const std::size_t take = std::min(inChunk, maxPoints - done);
            const std::size_t start = records.size();
            records.resize(start + take * outputLength);
            converter_->convert(chunk_.data() + chunkPoint_ * header_.recordLength, take,
                                records.data() + start);
            chunkPoint_ += take;
            done += take;
        }
        nextPoint_ += done;
        return done;
    }

    std::filesystem::path path_;
    std::optional<InputFile> file_;  // open while reading (see the constructor)
    std::uint64_t fileSize_;
    unsigned threads_;
    std::vector<std::byte> head_;
    LasHeader header_;
    PointRecordSourceInfo info_;
    std::optional<RecordConverter> converter_;
    std::optional<laz::LazLayout> layout_;
    std::vector<laz::Chunk> chunks_;
    std::unique_ptr<LazChunkStream> stream_;
    std::uint64_t nextPoint_ = 0;
    std::vector<std::byte> chunk_;  // raw records: the current LAZ chunk, or a block of a LAS file
    std::size_t chunkPoint_ = 0;    // the next record of the LAZ chunk
};

}  // namespace

std::unique_ptr<PointRecordSource> openLasRecordSource(const std::filesystem::path& path,
                                                       unsigned threads) {
    try {
        return std::make_unique<LasRecordSource>(path, threads);
    } catch (const Error& error) {
        throwNamed(path.string(), error);
    }
}

}  // namespace subscan
