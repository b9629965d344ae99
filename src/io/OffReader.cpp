#include "io/OffReader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/TextParsing.h"

namespace subscan {

namespace {

/// The lines of the file that hold something: comments ('#' to the end of the line) and blank
/// lines skipped, numbered from 1 for messages.
class MeaningfulLines {
  public:
    explicit MeaningfulLines(std::string_view text) : text_(text) {}

    /// The next line's words, or nullopt at the end of the file.
    std::optional<std::vector<std::string_view>> next() {
        while (position_ < text_.size()) {
            const std::size_t end = std::min(text_.find('\n', position_), text_.size());
            std::string_view line = text_.substr(position_, end - position_);
            position_ = end + 1;
            ++lineNumber_;
            line = line.substr(0, line.find('#'));
            std::vector<std::string_view> words = splitWords(line);
            if (!words.empty()) {
                return words;
            }
        }
        return std::nullopt;
    }

    std::size_t lineNumber() const { return lineNumber_; }
    std::size_t position() const { return position_; }

  private:
    std::string_view text_;
    std::size_t position_ = 0;
    std::size_t lineNumber_ = 0;
};

/// What the keyword announces each vertex line holds after x y z.
struct VertexLayout {
    bool textureCoordinates = false;  // ST
    bool color = false;               // C
    bool normal = false;              // N
    bool homogeneous = false;         // 4: x y z w
    std::string keyword;              // as written, for the format's description
};

/// The keyword's prefixes in their fixed order, or nullopt when `word` is not an OFF keyword.
std::optional<VertexLayout> parseKeyword(std::string_view word) {
    if (!word.ends_with("OFF")) {
        return std::nullopt;
    }
    VertexLayout layout;
    layout.keyword = std::string(word);
    std::string_view prefix = word.substr(0, word.size() - 3);
    const auto take = [&](std::string_view flag) {
        if (!prefix.starts_with(flag)) {
            return false;
        }
        prefix.remove_prefix(flag.size());
        return true;
    };
    layout.textureCoordinates = take("ST");
    layout.color = take("C");
    layout.normal = take("N");
    layout.homogeneous = take("4");
    if (take("n")) {
        throw Error(
            fmt::format("the OFF keyword '{}' announces vertices of another dimension "
                        "than 3, which subscan does not read",
                        word));
    }
    if (!prefix.empty()) {
        return std::nullopt;
    }
    return layout;
}

double numberAt(const std::vector<std::string_view>& words, std::size_t index,
                std::size_t lineNumber, std::string_view what) {
    double value = 0.0;
    const std::string_view word = words[index];
    if (parseNumber(word.data(), word.data() + word.size(), value) != word.data() + word.size()) {
        throw Error(fmt::format("line {}: the {} {} is not a number", lineNumber, what,
                                quoteForMessage(word)));
    }
    return value;
}

/// A count of the header: a non-negative integer that fits 32-bit point indices.
std::uint32_t countAt(const std::vector<std::string_view>& words, std::size_t index,
                      std::size_t lineNumber, std::string_view what) {
    const double value = numberAt(words, index, lineNumber, what);
    if (!(value >= 0.0 && value <= static_cast<double>(kMaxPoints) && std::floor(value) == value)) {
        throw Error(fmt::format("line {}: the {} {} is not a count from 0 to {}", lineNumber, what,
                                quoteForMessage(words[index]), kMaxPoints));
    }
    return static_cast<std::uint32_t>(value);
}

/// A vertex colour as written: 3 or 4 channels (RGB or RGBA).
struct WrittenColor {
    // Floats hold 0..255 exactly and 0..1 to 1e-7, far finer than a step of 1/255.
    std::array<float, 4> channels{};
    std::size_t count = 0;
};

/// Whether a file's colours are 0..1 floats or 0..255 integers is decided once for all of
/// them: white "1 1 1" in a file of "0.5 0.25 1" is 0..1 like its neighbours.
class ColorScale {
  public:
    /// Reads a vertex's colour words, noting whether they look like 0..1 floats.
    WrittenColor read(const std::vector<std::string_view>& words, std::size_t first,
                      std::size_t count, std::size_t lineNumber) {
        WrittenColor color;
        color.count = count;
        for (std::size_t c = 0; c < count; ++c) {
            const double value = numberAt(words, first + c, lineNumber, "colour");
            color.channels[c] = saturateToFloat(value);
            floatWords_ =
                floatWords_ || words[first + c].find_first_of(".eE") != std::string_view::npos;
            aboveOne_ = aboveOne_ || value > 1.0;
        }
        return color;
    }

    /// 0..1 when some colour is written with a decimal point or an exponent and none exceeds 1
    /// (a writer of 0..255 may print "255.0"), else 0..255.
    Rgba8 toRgba(const WrittenColor& color) const {
        const bool unit = floatWords_ && !aboveOne_;
        std::uint8_t channels[4] = {0, 0, 0, 255};
        for (std::size_t c = 0; c < color.count; ++c) {
            const float value = color.channels[c];
            const double scaled = std::clamp(unit ? value * 255.0 : value, 0.0, 255.0);
            channels[c] = static_cast<std::uint8_t>(std::lround(std::isnan(scaled) ? 0.0 : scaled));
        }
        return {channels[0], channels[1], channels[2], channels[3]};
    }

  private:
    bool floatWords_ = false;
    bool aboveOne_ = false;
};

class OffParser {
  public:
    OffParser(std::string_view text, ReadContext& context)
        : lines_(text), context_(context), size_(text.size()) {}

    PointCloud read() {
        std::vector<std::string_view> words = nextLine("the vertex and face counts");
        VertexLayout layout;
        if (const auto keyword = parseKeyword(words.front())) {
            layout = *keyword;
            if (words.size() > 1 && words[1] == "BINARY") {
                throw Error(
                    "binary OFF files are not supported; write the mesh as ASCII OFF or PLY");
            }
            words.erase(words.begin());
            if (words.empty()) {
                words = nextLine("the vertex and face counts");
            }
        } else {
            layout.keyword = "OFF";  // the keyword is optional; the counts come first
        }
        if (words.size() < 2) {
            throw Error(fmt::format("line {}: expected the vertex and face counts, found {}",
                                    lines_.lineNumber(), quoteForMessage(joined(words))));
        }
        const std::uint32_t vertices = countAt(words, 0, lines_.lineNumber(), "vertex count");
        const std::uint32_t faces = countAt(words, 1, lines_.lineNumber(), "face count");
        context_.formatDetail =
            fmt::format("{} (ASCII): {} vertices, {} faces", layout.keyword, vertices, faces);

        // A vertex line takes 6 bytes at the least ("0 0 0\n"): a count beyond what the file
        // can hold reserves no more than that, and the read then stops at the file's end.
        const std::size_t expected = std::min<std::size_t>(vertices, size_ / 6);
        PointCloudBuilder builder({.color = layout.color, .normal = layout.normal}, expected,
                                  faces > 0);
        readVertices(layout, vertices, builder);
        const std::size_t skipped = readFaces(vertices, faces, builder);
        if (skipped > 0) {
            context_.warnings.push_back(
                fmt::format("skipped {} faces with fewer than 3 vertices", skipped));
        }
        PointCloud cloud = builder.finish(context_.warnings);
        for (std::size_t i = 0; i < cloud.colors.size(); ++i) {
            cloud.colors[i] = colorScale_.toRgba(writtenColors_[i]);
        }
        return cloud;
    }

  private:
    static std::string joined(const std::vector<std::string_view>& words) {
        std::string text;
        for (const std::string_view word : words) {
            text += text.empty() ? "" : " ";
            text += word;
        }
        return text;
    }

    std::vector<std::string_view> nextLine(std::string_view expected) {
        auto words = lines_.next();
        if (!words) {
            throw Error(fmt::format("the OFF file ends before {} (file truncated?)", expected));
        }
        return std::move(*words);
    }

    void readVertices(const VertexLayout& layout, std::uint32_t count, PointCloudBuilder& builder) {
        const std::size_t coordinates = layout.homogeneous ? 4 : 3;
        const std::size_t normalAt = coordinates;
        const std::size_t colorAt = normalAt + (layout.normal ? 3 : 0);
        const std::size_t trailing = layout.textureCoordinates ? 2 : 0;
        for (std::uint32_t i = 0; i < count; ++i) {
            const auto words = nextLine(fmt::format("vertex {} of {}", i + 1, count));
            const std::size_t line = lines_.lineNumber();
            // A colour is 3 or 4 numbers (RGB or RGBA) between the normal and the texture
            // coordinates.
            const std::size_t colorWords =
                layout.color && words.size() >= colorAt + trailing
                    ? std::min<std::size_t>(words.size() - colorAt - trailing, 4)
                    : 0;
            if (words.size() < colorAt || (layout.color && colorWords < 3)) {
                throw Error(fmt::format("line {}: vertex {} has {} numbers; {} vertices have {}",
                                        line, i + 1, words.size(), layout.keyword,
                                        colorAt + (layout.color ? 3 : 0) + trailing));
            }
            PointRecord record;
            for (int axis = 0; axis < 3; ++axis) {
                record.position[axis] =
                    numberAt(words, static_cast<std::size_t>(axis), line, "coordinate");
            }
            if (layout.homogeneous) {
                record.position /= numberAt(words, 3, line, "coordinate w");
            }
            if (layout.normal) {
                for (int axis = 0; axis < 3; ++axis) {
                    record.normal[axis] = saturateToFloat(
                        numberAt(words, normalAt + static_cast<std::size_t>(axis), line, "normal"));
                }
            }
            const std::size_t kept = builder.validPoints();
            builder.add(record);
            // Read for every vertex, so that a dropped one's colour is judged too.
            if (layout.color) {
                const WrittenColor color = colorScale_.read(words, colorAt, colorWords, line);
                if (builder.validPoints() > kept) {
                    writtenColors_.push_back(color);
                }
            }
            if (i % (1u << 16) == 0) {
                context_.reportProgress(lines_.position(), size_);
            }
        }
    }

    /// Fans each polygon into triangles; returns how many had fewer than 3 vertices.
    std::size_t readFaces(std::uint32_t vertices, std::uint32_t count, PointCloudBuilder& builder) {
        std::size_t skipped = 0;
        std::vector<std::uint32_t> indices;
        for (std::uint32_t f = 0; f < count; ++f) {
            const auto words = nextLine(fmt::format("face {} of {}", f + 1, count));
            const std::size_t line = lines_.lineNumber();
            const std::uint32_t corners = countAt(words, 0, line, "face's vertex count");
            if (words.size() < 1 + static_cast<std::size_t>(corners)) {
                throw Error(fmt::format("line {}: face {} names {} vertices but lists {}", line,
                                        f + 1, corners, words.size() - 1));
            }
            indices.clear();
            for (std::uint32_t k = 0; k < corners; ++k) {
                const std::uint32_t index = countAt(words, 1 + k, line, "vertex index");
                if (index >= vertices) {
                    throw Error(fmt::format(
                        "line {}: face {} refers to vertex {}, outside 0..{} (the file has {} "
                        "vertices)",
                        line, f + 1, index, vertices == 0 ? 0 : vertices - 1, vertices));
                }
                indices.push_back(index);
            }
            if (indices.size() < 3) {
                ++skipped;
                continue;
            }
            for (std::size_t k = 1; k + 1 < indices.size(); ++k) {
                builder.addTriangle({indices[0], indices[k], indices[k + 1]});
            }
        }
        return skipped;
    }

    MeaningfulLines lines_;
    ReadContext& context_;
    std::size_t size_;
    ColorScale colorScale_;
    std::vector<WrittenColor> writtenColors_;  // of the vertices kept, until the scale is known
};

}  // namespace

PointCloud readOff(std::span<const std::byte> file, ReadContext& context) {
    const std::string_view text(reinterpret_cast<const char*>(file.data()), file.size());
    OffParser parser(text, context);
    return parser.read();
}

}  // namespace subscan
