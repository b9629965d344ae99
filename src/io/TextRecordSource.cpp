#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/InputFile.h"
#include "io/RecordSourceSupport.h"
#include "io/XyzReader.h"

// Text lists of points (XYZ, PTS, CSV...) as records, read in pieces of whole lines: a first
// pass counts the points and finds their bounds, which choose the quantization, and the colour
// encoding; each read then parses lines until it has the points asked for.
namespace subscan {

namespace {

/// The start of the file that decides the layout: header lines and a hundred point lines fit
/// many times over.
constexpr std::size_t kTextHeadBytes = 4u << 20;
/// Text parsed at once; a line longer than this is read whole all the same.
constexpr std::size_t kTextPieceBytes = 1u << 20;
/// A point line is at most a few hundred bytes: text without a line end for this long is not a
/// list of points, and must not be held whole.
constexpr std::size_t kLongestTextLine = 64u << 20;

/// A text file from an offset on, in pieces that end at a line end (or the file's end).
class LinePieces {
  public:
    LinePieces(const InputFile& file, std::uint64_t offset) : file_(file), position_(offset) {}

    /// The next piece, or false at the end of the file.
    bool next(std::string_view& piece) {
        // What is left of the last piece has no line end: only new bytes need a search.
        buffer_.erase(0, used_);
        used_ = 0;
        std::size_t lineEnd = std::string::npos;
        for (;;) {
            const bool atEnd = position_ == file_.size();
            if (lineEnd != std::string::npos && (buffer_.size() >= kTextPieceBytes || atEnd)) {
                used_ = lineEnd + 1;
                break;
            }
            if (atEnd) {
                used_ = buffer_.size();  // the last line, without its line end
                break;
            }
            if (buffer_.size() > kLongestTextLine) {
                throw Error(fmt::format(
                    "it has a line longer than {} MiB (from byte {} on): it is not a text list of "
                    "points",
                    kLongestTextLine >> 20, position_ - buffer_.size()));
            }
            const std::size_t start = buffer_.size();
            const auto size = static_cast<std::size_t>(
                std::min<std::uint64_t>(kTextPieceBytes, file_.size() - position_));
            buffer_.resize(start + size);
            file_.read(position_, std::as_writable_bytes(std::span(buffer_)).subspan(start));
            position_ += size;
            const std::size_t found = std::string_view(buffer_).substr(start).rfind('\n');
            if (found != std::string_view::npos) {
                lineEnd = start + found;
            }
        }
        piece = std::string_view(buffer_).substr(0, used_);
        return !piece.empty();
    }

  private:
    const InputFile& file_;
    std::uint64_t position_;
    std::string buffer_;
    std::size_t used_ = 0;  // the bytes of buffer_ given out last
};

/// The start of the file cut after its last whole line (all of a small file).
std::string readTextHead(const InputFile& file) {
    std::string head(static_cast<std::size_t>(std::min<std::uint64_t>(kTextHeadBytes, file.size())),
                     '\0');
    file.read(0, std::as_writable_bytes(std::span(head)));
    if (head.size() < file.size()) {
        const std::size_t lineEnd = head.rfind('\n');
        if (lineEnd == std::string::npos) {
            throw Error(
                fmt::format("its first {} MiB hold no line end: it is not a text list of points",
                            kTextHeadBytes >> 20));
        }
        head.resize(lineEnd + 1);
    }
    return head;
}

class TextRecordSource final : public ConvertedRecordSource {
  public:
    TextRecordSource(const std::filesystem::path& path) : file_(path) {
        const std::string name = path.string();
        ReadContext context;
        start(context);
        std::vector<std::string> warnings;
        for (const std::string& warning : context.warnings) {
            warnings.push_back(fmt::format("{}: {}", name, warning));
        }
        const PointTextLayout& layout = reader_->layout();
        Bounds bounds;
        std::uint64_t count = 0;
        TextColorRange colors;
        bool intensitiesFit = true;
        parseAll([&](std::span<const double> values, std::size_t line) {
            if (layout.color) {
                for (const std::size_t column : *layout.color) {
                    colors.add(values[column]);
                }
            }
            if (layout.intensity) {
                intensitiesFit = intensitiesFit && fitsIntensityWord(values[*layout.intensity]);
            }
            const glm::dvec3 p = position(values);
            for (int axis = 0; axis < 3; ++axis) {
                if (!std::isfinite(p[axis])) {
                    throw Error(fmt::format(
                        "line {} has the {} coordinate {}; LAS records need finite coordinates",
                        line, "xyz"[axis], p[axis]));
                }
            }
            bounds.add(p);
            ++count;
        });
        if (count == 0) {
            throw Error("it holds no points, only PTS count lines");
        }
        colorEncoding_ = layout.colorEncodingFromName ? layout.colorEncoding : colors.encoding();
        if (!intensitiesFit) {
            warnings.push_back(intensitiesNotKept(name));
        }
        startRecords(name, count, layout.color.has_value(), layout.normal.has_value(), bounds,
                     reader_->coordinateStep(), std::move(warnings));
        rewind();
    }

    std::size_t read(std::vector<std::byte>& records, std::size_t maxPoints) override {
        try {
            const std::size_t recordLength = info().format.recordLength();
            std::size_t done = 0;
            while (done < maxPoints) {
                if (pendingPoint_ == pending_.size() / recordLength) {
                    pending_.clear();
                    pendingPoint_ = 0;
                    std::string_view piece;
                    if (!pieces_->next(piece)) {
                        break;
                    }
                    reader_->parse(piece, [&](std::span<const double> values, std::size_t) {
                        writer().append(pending_, point(values));
                    });
                    continue;
                }
                const std::size_t take =
                    std::min(pending_.size() / recordLength - pendingPoint_, maxPoints - done);
                const auto first =
                    pending_.begin() + static_cast<std::ptrdiff_t>(pendingPoint_ * recordLength);
                records.insert(records.end(), first,
                               first + static_cast<std::ptrdiff_t>(take * recordLength));
                pendingPoint_ += take;
                done += take;
            }
            return done;
        } catch (const Error& error) {
            throwNamed(info().name, error);
        }
    }

    void rewind() override {
        ReadContext context;
        start(context);
        pending_.clear();
        pendingPoint_ = 0;
    }

  private:
    /// A reader at the first point line.
    void start(ReadContext& context) {
        const std::string head = readTextHead(file_);
        reader_.emplace(head, context);
        pieces_.emplace(file_, reader_->dataOffset());
    }

    void parseAll(const std::function<void(std::span<const double>, std::size_t)>& point) {
        std::string_view piece;
        while (pieces_->next(piece)) {
            reader_->parse(piece, point);
        }
        reader_->finish();
    }

    glm::dvec3 position(std::span<const double> values) const {
        const auto& p = reader_->layout().position;
        return {values[p[0]], values[p[1]], values[p[2]]};
    }

    ConvertedPoint point(std::span<const double> values) const {
        const PointTextLayout& layout = reader_->layout();
        ConvertedPoint point;
        point.position = position(values);
        if (layout.color) {
            for (int k = 0; k < 3; ++k) {
                const double value = values[(*layout.color)[k]];
                point.rgb[k] =
                    colorEncoding_ == TextColorEncoding::UnitFloat ? colorWordFromUnit(value)
                    : colorEncoding_ == TextColorEncoding::Word16  ? colorWordFromWord(value)
                                                                   : colorWordFromByte(value);
            }
        }
        if (layout.normal) {
            const auto& n = *layout.normal;
            point.normal = {saturateToFloat(values[n[0]]), saturateToFloat(values[n[1]]),
                            saturateToFloat(values[n[2]])};
        }
        if (layout.intensity) {
            point.intensity = intensityWord(values[*layout.intensity]);
        }
        return point;
    }

    InputFile file_;
    std::optional<PointTextReader> reader_;
    std::optional<LinePieces> pieces_;
    // From every colour value of the first pass; the reader's layout has the first lines' guess.
    TextColorEncoding colorEncoding_ = TextColorEncoding::Byte;
    std::vector<std::byte> pending_;  // the records of the piece parsed last
    std::size_t pendingPoint_ = 0;    // the next of them to give out
};

}  // namespace

std::unique_ptr<PointRecordSource> openTextRecordSource(const std::filesystem::path& path) {
    try {
        return std::make_unique<TextRecordSource>(path);
    } catch (const Error& error) {
        throwNamed(path.string(), error);
    }
}

}  // namespace subscan
