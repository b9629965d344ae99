#include "io/XyzReader.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <fast_float/fast_float.h>
#include <fmt/format.h>

#include "core/Error.h"
#include "io/TextParsing.h"

namespace subscan {

namespace {

/// Point lines at the start that decide the layout guesses, the separators and the size estimate.
constexpr std::size_t kSampleLines = 100;
/// How much of a file format detection and the binary check look at.
constexpr std::size_t kSniffBytes = 4096;
constexpr std::size_t kProgressBytes = 4u << 20;
/// Header lines longer than this are not read for column names.
constexpr std::size_t kLongestHeaderLine = 64 * 1024;
/// Normals printed with only 2 decimals miss unit length by up to 0.005 * sqrt(3) ~ 0.009; twice
/// that still rejects colours and other data, which are almost never all this close to 1.
constexpr double kUnitLengthTolerance = 0.02;

constexpr std::string_view kUtf8ByteOrderMark = "\xEF\xBB\xBF";

std::string pluralValues(std::size_t count) {
    return fmt::format("{} value{}", count, count == 1 ? "" : "s");
}

/// Which characters separate values besides blanks. Files written with a decimal comma (German
/// or French spreadsheets) separate values with ';', so ',' then belongs to the numbers.
struct Separators {
    bool decimalComma = false;

    bool isSeparator(char c) const { return c == ';' || (c == ',' && !decimalComma); }
    char decimalPoint() const { return decimalComma ? ',' : '.'; }
};

/// Parses one number starting exactly at `first` with fast_float, like parseNumber but with
/// either decimal point. Returns the end of the number, or nullptr when there is none.
const char* parseValueSlowly(const char* first, const char* last, char decimalPoint,
                             double& value) {
    const char* start = first;
    if (start != last && *start == '+') {
        ++start;  // fast_float rejects a leading '+', which some exporters write.
        if (start != last && (*start == '+' || *start == '-')) {
            return nullptr;
        }
    }
    const fast_float::parse_options options(fast_float::chars_format::general, decimalPoint);
    const fast_float::from_chars_result result =
        fast_float::from_chars_advanced(start, last, value, options);
    if (result.ec != std::errc() || result.ptr == start) {
        return nullptr;
    }
    return result.ptr;
}

bool isDigit(char c) {
    return c >= '0' && c <= '9';
}

/// Like parseValueSlowly, but plain decimals such as "-73.127151" or "255", which make up
/// nearly every file, skip fast_float's general machinery: when the digits form an integer of
/// at most 2^53 and there are at most 22 decimals, integer and power of ten are exact doubles and
/// one IEEE division rounds correctly, so the value is the same as fast_float's (Clinger's fast
/// path). Anything else (exponents, nan, long mantissas) goes to fast_float.
const char* parseValue(const char* first, const char* last, char decimalPoint, double& value) {
    static constexpr double kPowersOfTen[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                              1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                              1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    constexpr std::uint64_t kLargestExactInteger = std::uint64_t{1} << 53;
    constexpr std::ptrdiff_t kMostDigitsWithoutOverflow = 19;
    const char* p = first;
    const bool negative = p != last && *p == '-';
    if (negative) {
        ++p;
    }
    std::uint64_t mantissa = 0;
    const char* digitsStart = p;
    while (p != last && isDigit(*p)) {
        mantissa = mantissa * 10 + static_cast<std::uint64_t>(*p - '0');
        ++p;
    }
    std::ptrdiff_t digits = p - digitsStart;
    std::ptrdiff_t decimals = 0;
    if (p != last && *p == decimalPoint) {
        ++p;
        const char* decimalsStart = p;
        while (p != last && isDigit(*p)) {
            mantissa = mantissa * 10 + static_cast<std::uint64_t>(*p - '0');
            ++p;
        }
        decimals = p - decimalsStart;
        digits += decimals;
    }
    const bool exponent = p != last && (*p == 'e' || *p == 'E');
    if (digits == 0 || digits > kMostDigitsWithoutOverflow || mantissa > kLargestExactInteger ||
        decimals >= static_cast<std::ptrdiff_t>(std::size(kPowersOfTen)) || exponent) {
        return parseValueSlowly(first, last, decimalPoint, value);
    }
    const double magnitude = static_cast<double>(mantissa) / kPowersOfTen[decimals];
    value = negative ? -magnitude : magnitude;
    return p;
}

/// How many decimals a number's text gives, less its exponent: 3 for "512345.125" and
/// "512345.000", 0 for "17", -2 for "1.5e3". 10^-decimals is the step the text resolves.
int writtenDecimals(const char* first, const char* last, char decimalPoint) {
    const char* p = std::find(first, last, decimalPoint);
    int decimals = 0;
    if (p != last) {
        for (++p; p != last && isDigit(*p); ++p) {
            ++decimals;
        }
    }
    p = std::find_if(first, last, [](char c) { return c == 'e' || c == 'E'; });
    if (p != last) {
        int exponent = 0;
        std::from_chars(p + 1 + (p + 1 != last && p[1] == '+'), last, exponent);
        decimals -= exponent;
    }
    return decimals;
}

/// True when all of `field` is one number.
bool isNumber(std::string_view field, Separators separators, double* value = nullptr) {
    double parsed = 0.0;
    const char* end = field.data() + field.size();
    if (field.empty() || parseValue(field.data(), end, separators.decimalPoint(), parsed) != end) {
        return false;
    }
    if (value != nullptr) {
        *value = parsed;
    }
    return true;
}

std::string_view trimBlanks(std::string_view text) {
    while (!text.empty() && isBlank(text.front())) {
        text.remove_prefix(1);
    }
    while (!text.empty() && isBlank(text.back())) {
        text.remove_suffix(1);
    }
    return text;
}

/// `content` starts with a non-blank character.
bool isComment(std::string_view content) {
    return content.starts_with('#') || content.starts_with("//");
}

std::string_view withoutCommentMarker(std::string_view content) {
    content.remove_prefix(content.starts_with('#') ? 1 : 2);
    return content;
}

/// Splits a text into lines without their '\n' (nor the '\r' of a CRLF). memchr finds the line
/// ends, so this costs little next to parsing the numbers.
class LineReader {
  public:
    LineReader(std::string_view text, std::size_t offset, std::size_t linesBefore)
        : text_(text), position_(offset), lineNumber_(linesBefore) {}

    bool next(std::string_view& line) {
        if (position_ >= text_.size()) {
            return false;
        }
        const char* start = text_.data() + position_;
        const std::size_t left = text_.size() - position_;
        const auto* newline = static_cast<const char*>(std::memchr(start, '\n', left));
        std::size_t length = newline != nullptr ? static_cast<std::size_t>(newline - start) : left;
        lineStart_ = position_;
        position_ += length + (newline != nullptr ? 1 : 0);
        terminated_ = newline != nullptr;
        if (length > 0 && start[length - 1] == '\r') {
            --length;
        }
        line = {start, length};
        ++lineNumber_;
        return true;
    }

    /// 1-based number of the line last returned.
    std::size_t lineNumber() const { return lineNumber_; }
    std::size_t lineStart() const { return lineStart_; }
    /// Offset just past the line last returned and its line end.
    std::size_t position() const { return position_; }
    /// False when the line last returned ran to the end of the text without a '\n'.
    bool terminated() const { return terminated_; }

  private:
    std::string_view text_;
    std::size_t position_;
    std::size_t lineNumber_;
    std::size_t lineStart_ = 0;
    bool terminated_ = false;
};

/// Walks the fields of one line. Fields are separated by blanks, or by one separator with
/// optional blanks around it; two separators in a row leave an empty field between them, and a
/// separator at the end of the line is tolerated (some CSV writers leave one).
class FieldScanner {
  public:
    FieldScanner(std::string_view line, Separators separators)
        : position_(line.data()), end_(line.data() + line.size()), separators_(separators) {}

    /// The next field, "" for an empty one, or nullopt at the end of the line.
    std::optional<std::string_view> next() {
        skipBlanks();
        if (position_ == end_) {
            return std::nullopt;
        }
        if (separators_.isSeparator(*position_)) {
            return std::string_view(position_++, 0);
        }
        const char* start = position_;
        while (position_ != end_ && !isBlank(*position_) && !separators_.isSeparator(*position_)) {
            ++position_;
        }
        const std::string_view field(start, static_cast<std::size_t>(position_ - start));
        skipBlanks();
        if (position_ != end_ && separators_.isSeparator(*position_)) {
            ++position_;
        }
        return field;
    }

  private:
    void skipBlanks() {
        while (position_ != end_ && isBlank(*position_)) {
            ++position_;
        }
    }

    const char* position_;
    const char* end_;
    Separators separators_;
};

/// The field that starts at `start`, as FieldScanner would cut it.
std::string_view fieldAt(const char* start, const char* lineEnd, Separators separators) {
    const char* end = start;
    while (end != lineEnd && !isBlank(*end) && !separators.isSeparator(*end)) {
        ++end;
    }
    return {start, static_cast<std::size_t>(end - start)};
}

[[noreturn]] void throwBadField(std::string_view field, std::string_view line,
                                std::size_t lineNumber) {
    if (line.find('\0') != std::string_view::npos) {
        throw Error(
            fmt::format("line {} contains NUL bytes: the file is binary or damaged, not a "
                        "text list of points",
                        lineNumber));
    }
    if (field.empty()) {
        throw Error(fmt::format("line {} has an empty value (a separator with no number before it)",
                                lineNumber));
    }
    throw Error(
        fmt::format("line {} has the non-numeric value {}", lineNumber, quoteForMessage(field)));
}

/// Counts the fields of a line that should be all numbers; throws at the first one that is not.
/// `firstValue` receives the first number.
std::size_t countNumbers(std::string_view content, Separators separators, std::size_t lineNumber,
                         double& firstValue) {
    FieldScanner fields(content, separators);
    std::size_t count = 0;
    while (const auto field = fields.next()) {
        double value = 0.0;
        if (!isNumber(*field, separators, &value)) {
            throwBadField(*field, content, lineNumber);
        }
        if (count == 0) {
            firstValue = value;
        }
        ++count;
    }
    return count;
}

/// Like countNumbers, but nullopt instead of an error.
std::optional<std::size_t> countNumbersIfAll(std::string_view content, Separators separators) {
    FieldScanner fields(content, separators);
    std::size_t count = 0;
    while (const auto field = fields.next()) {
        if (!isNumber(*field, separators)) {
            return std::nullopt;
        }
        ++count;
    }
    return count;
}

/// A header line's first non-empty field is a word, where a data line has a number.
bool startsWithWord(std::string_view content, Separators separators) {
    FieldScanner fields(content, separators);
    while (const auto field = fields.next()) {
        if (!field->empty()) {
            return !isNumber(*field, separators);
        }
    }
    return false;
}

/// A PTS count line: one non-negative integer (below 2^53, where doubles stop being exact).
bool isCount(double value) {
    return value >= 0.0 && value <= 9007199254740992.0 && value == std::floor(value);
}

// ---------------------------------------------------------------------------------------------
// Column layout

enum class Role : std::uint8_t {
    X,
    Y,
    Z,
    Red,
    Green,
    Blue,
    RedUnit,
    GreenUnit,
    BlueUnit,
    NormalX,
    NormalY,
    NormalZ,
    Intensity,
    Count
};

std::optional<Role> roleFromName(std::string_view lowercaseName) {
    static constexpr std::array<std::pair<std::string_view, Role>, 24> kNames{{
        {"x", Role::X},
        {"y", Role::Y},
        {"z", Role::Z},
        {"r", Role::Red},
        {"red", Role::Red},
        {"g", Role::Green},
        {"green", Role::Green},
        {"b", Role::Blue},
        {"blue", Role::Blue},
        {"rf", Role::RedUnit},
        {"gf", Role::GreenUnit},
        {"bf", Role::BlueUnit},
        {"nx", Role::NormalX},
        {"ny", Role::NormalY},
        {"nz", Role::NormalZ},
        {"normal_x", Role::NormalX},
        {"normal_y", Role::NormalY},
        {"normal_z", Role::NormalZ},
        {"normalx", Role::NormalX},
        {"normaly", Role::NormalY},
        {"normalz", Role::NormalZ},
        {"i", Role::Intensity},
        {"intensity", Role::Intensity},
        {"scalar_intensity", Role::Intensity},
    }};
    for (const auto& [name, role] : kNames) {
        if (name == lowercaseName) {
            return role;
        }
    }
    return std::nullopt;
}

using ColorEncoding = TextColorEncoding;
using ColumnTriple = std::array<std::size_t, 3>;
using Layout = PointTextLayout;

/// The columns read, in file order, e.g. "x y z i r g b".
std::string describeLayout(const Layout& layout) {
    std::vector<std::pair<std::size_t, std::string_view>> named;
    const auto addTriple = [&](const ColumnTriple& columns, std::array<std::string_view, 3> n) {
        for (int k = 0; k < 3; ++k) {
            named.emplace_back(columns[k], n[k]);
        }
    };
    addTriple(layout.position, {"x", "y", "z"});
    if (layout.color) {
        addTriple(*layout.color, layout.colorEncoding == ColorEncoding::UnitFloat
                                     ? std::array<std::string_view, 3>{"rf", "gf", "bf"}
                                     : std::array<std::string_view, 3>{"r", "g", "b"});
    }
    if (layout.normal) {
        addTriple(*layout.normal, {"nx", "ny", "nz"});
    }
    if (layout.intensity) {
        named.emplace_back(*layout.intensity, "i");
    }
    std::sort(named.begin(), named.end());
    std::string text;
    for (const auto& [column, name] : named) {
        text += text.empty() ? "" : " ";
        text += name;
    }
    if (layout.color && layout.colorEncoding == ColorEncoding::Word16) {
        text += " (16-bit colour)";
    }
    if (layout.columnCount > named.size()) {
        const std::size_t ignored = layout.columnCount - named.size();
        text += fmt::format(", {} other column{} ignored", ignored, ignored == 1 ? "" : "s");
    }
    return text;
}

/// A line before the data that names columns (it has x, y and z among its words).
struct HeaderLine {
    std::size_t lineNumber = 0;
    std::vector<std::string> names;  // as written, without quotes
};

std::optional<HeaderLine> parseHeaderNames(std::string_view content, std::size_t lineNumber) {
    HeaderLine header;
    header.lineNumber = lineNumber;
    bool hasX = false, hasY = false, hasZ = false;
    FieldScanner fields(content, Separators{});
    while (auto field = fields.next()) {
        std::string_view name = *field;
        if (name.size() >= 2 && (name.front() == '"' || name.front() == '\'') &&
            name.back() == name.front()) {
            name = name.substr(1, name.size() - 2);
        }
        const std::string lowercase = asciiLowercase(name);
        hasX = hasX || lowercase == "x";
        hasY = hasY || lowercase == "y";
        hasZ = hasZ || lowercase == "z";
        header.names.emplace_back(name);
    }
    if (!(hasX && hasY && hasZ)) {
        return std::nullopt;
    }
    return header;
}

/// Maps columns by the names of a header line; names it does not know are reported as ignored.
Layout layoutFromNames(const HeaderLine& header, std::vector<std::string>& warnings) {
    std::array<std::optional<std::size_t>, static_cast<std::size_t>(Role::Count)> columnOf;
    for (std::size_t column = 0; column < header.names.size(); ++column) {
        if (const auto role = roleFromName(asciiLowercase(header.names[column]))) {
            auto& slot = columnOf[static_cast<std::size_t>(*role)];
            if (!slot) {
                slot = column;
            }
        }
    }
    const auto column = [&](Role role) { return columnOf[static_cast<std::size_t>(role)]; };
    const auto triple = [&](Role a, Role b, Role c) -> std::optional<ColumnTriple> {
        if (column(a) && column(b) && column(c)) {
            return ColumnTriple{*column(a), *column(b), *column(c)};
        }
        return std::nullopt;
    };

    Layout layout;
    layout.columnCount = header.names.size();
    layout.position = *triple(Role::X, Role::Y, Role::Z);
    layout.color = triple(Role::Red, Role::Green, Role::Blue);
    if (!layout.color) {
        layout.color = triple(Role::RedUnit, Role::GreenUnit, Role::BlueUnit);
        layout.colorEncoding = ColorEncoding::UnitFloat;
        layout.colorEncodingFromName = layout.color.has_value();
    }
    layout.normal = triple(Role::NormalX, Role::NormalY, Role::NormalZ);
    layout.intensity = column(Role::Intensity);

    std::vector<bool> used(layout.columnCount, false);
    for (const std::size_t c : layout.position) {
        used[c] = true;
    }
    for (const auto& group : {layout.color, layout.normal}) {
        if (group) {
            for (const std::size_t c : *group) {
                used[c] = true;
            }
        }
    }
    if (layout.intensity) {
        used[*layout.intensity] = true;
    }
    std::vector<std::string> ignored;
    for (std::size_t c = 0; c < layout.columnCount; ++c) {
        if (!used[c]) {
            ignored.push_back(quoteForMessage(header.names[c]));
        }
    }
    if (!ignored.empty()) {
        warnings.push_back(fmt::format("the column{} {} named on line {} {} not read",
                                       ignored.size() == 1 ? "" : "s", fmt::join(ignored, ", "),
                                       header.lineNumber, ignored.size() == 1 ? "is" : "are"));
    }
    return layout;
}

/// The first point lines, checked to hold exactly `columnCount` numbers each.
struct Sample {
    std::vector<std::string_view> lines;
    std::size_t bytes = 0;  // including line ends
    Separators separators;

    std::vector<double> column(std::size_t index) const {
        std::vector<double> values;
        for (const std::string_view line : lines) {
            FieldScanner fields(line, separators);
            for (std::size_t k = 0; k < index; ++k) {
                fields.next();
            }
            double value = 0.0;
            isNumber(*fields.next(), separators, &value);
            values.push_back(value);
        }
        return values;
    }
};

/// Without a header, 6 columns are x y z plus either colour or a normal; the values tell which.
Layout guessSixColumns(const Sample& sample) {
    const std::vector<double> a = sample.column(3), b = sample.column(4), c = sample.column(5);
    bool colorLike = true;
    bool normalLike = true;
    bool anyUnit = false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        for (const double v : {a[i], b[i], c[i]}) {
            colorLike = colorLike && v >= 0.0 && v <= 255.0 && v == std::floor(v);
        }
        const double length = std::sqrt(a[i] * a[i] + b[i] * b[i] + c[i] * c[i]);
        // Some exporters write 0 0 0 for points without a normal.
        const bool unit = std::abs(length - 1.0) <= kUnitLengthTolerance;
        anyUnit = anyUnit || unit;
        normalLike = normalLike && (unit || length == 0.0);
    }
    normalLike = normalLike && anyUnit;
    Layout layout;
    layout.columnCount = 6;
    // Integer unit vectors (0 0 1) pass both tests; as colours they would be nearly black.
    if (normalLike) {
        layout.normal = ColumnTriple{3, 4, 5};
    } else if (colorLike) {
        layout.color = ColumnTriple{3, 4, 5};
    } else {
        throw Error(
            "the 3 values after x y z cannot be interpreted: on the first lines they are "
            "neither integer colours in 0..255 nor unit-length normals; add a header line "
            "such as 'x y z r g b' or 'x y z nx ny nz'");
    }
    return layout;
}

/// The layout of a file without a usable header, from its number of columns.
Layout guessLayout(std::size_t columnCount, const Sample& sample,
                   std::vector<std::string>& warnings) {
    Layout layout;
    layout.columnCount = columnCount;
    switch (columnCount) {
        case 3:
            break;
        case 4:
            layout.intensity = 3;
            break;
        case 6:
            return guessSixColumns(sample);
        case 7:  // Leica PTS
            layout.intensity = 3;
            layout.color = ColumnTriple{4, 5, 6};
            break;
        case 9:
            layout.color = ColumnTriple{3, 4, 5};
            layout.normal = ColumnTriple{6, 7, 8};
            break;
        case 10:
            layout.intensity = 3;
            layout.color = ColumnTriple{4, 5, 6};
            layout.normal = ColumnTriple{7, 8, 9};
            break;
        default:
            warnings.push_back(fmt::format(
                "each point line has {} values and no header names them; only the first 3 are "
                "read, as x y z, and the other {} are ignored",
                columnCount, columnCount - 3));
            break;
    }
    return layout;
}

ColorEncoding guessColorEncoding(const Layout& layout, const Sample& sample) {
    TextColorRange range;
    for (const std::size_t column : *layout.color) {
        for (const double v : sample.column(column)) {
            range.add(v);
        }
    }
    return range.encoding();
}

std::uint8_t toColorChannel(double value, ColorEncoding encoding) {
    double scaled = value;
    if (encoding == ColorEncoding::UnitFloat) {
        scaled = value * 255.0;
    } else if (encoding == ColorEncoding::Word16) {
        scaled = value / 257.0;
    }
    if (!(scaled > 0.0)) {
        return 0;  // also NaN
    }
    return static_cast<std::uint8_t>(std::min(255.0, scaled + 0.5));
}

// ---------------------------------------------------------------------------------------------
// Reading

/// What the lines before the points and the first point lines tell.
struct Prelude {
    std::size_t dataOffset = 0;       // start of the first point line, or PTS count line
    std::size_t linesBeforeData = 0;  // number of the line before it
    bool pts = false;                 // the data starts with a count line
    std::size_t columnCount = 0;      // 0: a PTS file with count lines only
    std::size_t firstPointLine = 0;
    std::optional<HeaderLine> header;
    Sample sample;
};

[[noreturn]] void throwTooFewValues(std::size_t count, std::size_t lineNumber) {
    throw Error(fmt::format("line {} has only {}; each point needs at least x, y and z", lineNumber,
                            pluralValues(count)));
}

void rejectLoneCarriageReturns(std::string_view content, std::size_t lineNumber) {
    if (content.find('\r') != std::string_view::npos) {
        throw Error(
            fmt::format("line {} contains a carriage return in the middle; if the lines end "
                        "with CR alone (classic Mac OS), convert the line ends to LF or CRLF",
                        lineNumber));
    }
}

/// Keeps the column names of a header line, if it names x, y and z.
void considerHeaderLine(std::string_view content, std::size_t lineNumber, Prelude& prelude) {
    // ESRI ASCII grids share the .asc extension with point lists, but hold a raster.
    constexpr std::string_view kGridKeyword = "ncols";
    if (asciiLowercase(content.substr(0, kGridKeyword.size())) == kGridKeyword &&
        (content.size() == kGridKeyword.size() || isBlank(content[kGridKeyword.size()]))) {
        throw Error(
            "it is an ESRI ASCII grid (a raster with an 'ncols' header), not a list of "
            "points");
    }
    if (content.size() > kLongestHeaderLine) {
        return;  // text, but no header: keeping its words could take gigabytes
    }
    if (auto names = parseHeaderNames(content, lineNumber)) {
        prelude.header = std::move(names);
    }
}

Prelude readPrelude(std::string_view text, std::size_t start) {
    Prelude prelude;
    LineReader lines(text, start, 0);
    std::string_view line;
    std::size_t headerOrCommentLines = 0;
    bool foundData = false;
    while (lines.next(line)) {
        const std::string_view content = trimBlanks(line);
        if (content.empty()) {
            continue;
        }
        rejectLoneCarriageReturns(content, lines.lineNumber());
        if (isComment(content)) {
            ++headerOrCommentLines;
            considerHeaderLine(withoutCommentMarker(content), lines.lineNumber(), prelude);
            continue;
        }
        if (content.find('\0') != std::string_view::npos) {
            throwBadField({}, content, lines.lineNumber());
        }
        if (startsWithWord(content, Separators{})) {
            ++headerOrCommentLines;
            considerHeaderLine(content, lines.lineNumber(), prelude);
            continue;
        }
        foundData = true;
        prelude.dataOffset = lines.lineStart();
        prelude.linesBeforeData = lines.lineNumber() - 1;
        break;
    }
    if (!foundData) {
        if (headerOrCommentLines > 0) {
            throw Error(fmt::format("it contains no points, only {} header or comment line{}",
                                    headerOrCommentLines, headerOrCommentLines == 1 ? "" : "s"));
        }
        throw Error("it contains no points, only blank lines");
    }

    // The raw lines from the first data line on; PTS count lines (one word) do not count
    // towards the sample size.
    struct RawLine {
        std::string_view content;
        std::size_t number;
        std::size_t bytes;
    };
    std::vector<RawLine> raw;
    std::size_t pointLike = 0;
    bool semicolons = false;
    bool commas = false;
    bool commasOnlyInNumbers = true;
    bool dots = false;
    LineReader dataLines(text, prelude.dataOffset, prelude.linesBeforeData);
    while (pointLike < kSampleLines && dataLines.next(line)) {
        const std::string_view content = trimBlanks(line);
        if (content.empty() || isComment(content)) {
            continue;
        }
        raw.push_back(
            {content, dataLines.lineNumber(), dataLines.position() - dataLines.lineStart()});
        if (content.find_first_of(" \t,;") != std::string_view::npos) {
            ++pointLike;
        }
        const bool lineHasSemicolon = content.find(';') != std::string_view::npos;
        semicolons = semicolons || lineHasSemicolon;
        dots = dots || content.find('.') != std::string_view::npos;
        for (std::size_t comma = content.find(','); comma != std::string_view::npos;
             comma = content.find(',', comma + 1)) {
            commas = true;
            commasOnlyInNumbers = commasOnlyInNumbers && lineHasSemicolon && comma > 0 &&
                                  comma + 1 < content.size() &&
                                  std::isdigit(static_cast<unsigned char>(content[comma - 1])) &&
                                  std::isdigit(static_cast<unsigned char>(content[comma + 1]));
        }
    }
    // "1,5;2,5;3,5": commas only ever inside numbers of ';'-separated lines, and no '.' at all.
    Separators separators;
    separators.decimalComma = semicolons && commas && commasOnlyInNumbers && !dots;
    prelude.sample.separators = separators;

    for (std::size_t i = 0; i < raw.size(); ++i) {
        const RawLine& current = raw[i];
        const bool mustBeValid = i == 0 || prelude.columnCount == 0;
        std::size_t count = 0;
        double firstValue = 0.0;
        if (mustBeValid) {
            rejectLoneCarriageReturns(current.content, current.number);
            count = countNumbers(current.content, separators, current.number, firstValue);
        } else if (const auto all = countNumbersIfAll(current.content, separators)) {
            count = *all;
        } else {
            break;  // the main pass reports it, after the lines before it
        }
        if (i == 0 && count == 1) {
            if (!isCount(firstValue)) {
                throwTooFewValues(count, current.number);
            }
            prelude.pts = true;
            continue;
        }
        if (prelude.pts && count == 1) {
            continue;  // the next block's count line
        }
        if (prelude.columnCount == 0) {
            if (count < 3) {
                throwTooFewValues(count, current.number);
            }
            prelude.columnCount = count;
            prelude.firstPointLine = current.number;
        } else if (count != prelude.columnCount) {
            break;
        }
        prelude.sample.lines.push_back(current.content);
        prelude.sample.bytes += current.bytes;
    }
    return prelude;
}

Layout chooseLayout(const Prelude& prelude, std::vector<std::string>& warnings) {
    if (prelude.columnCount == 0) {
        return {};
    }
    Layout layout;
    const std::optional<HeaderLine>& header = prelude.header;
    if (header && header->names.size() == prelude.columnCount) {
        layout = layoutFromNames(*header, warnings);
    } else {
        if (header) {
            warnings.push_back(fmt::format(
                "the header on line {} names {} columns, but the points have {}; the columns "
                "are guessed from the values instead",
                header->lineNumber, header->names.size(), pluralValues(prelude.columnCount)));
        }
        layout = guessLayout(prelude.columnCount, prelude.sample, warnings);
    }
    if (layout.color && !layout.colorEncodingFromName) {
        layout.colorEncoding = guessColorEncoding(layout, prelude.sample);
    }
    return layout;
}

/// A PTS block: a count line and the points after it.
struct PtsBlock {
    std::size_t countLine = 0;
    std::uint64_t declared = 0;
    std::uint64_t points = 0;

    void check() const {
        if (points != declared) {
            throw Error(fmt::format("the PTS count on line {} says {} point{}, but {} follow",
                                    countLine, declared, declared == 1 ? "" : "s", points));
        }
    }
};

/// Parses point lines and PTS count lines, piece after piece.
class PointLineParser {
  public:
    PointLineParser(const Prelude& prelude, const Layout& layout)
        : separators_(prelude.sample.separators),
          pts_(prelude.pts),
          firstPointLine_(prelude.firstPointLine),
          columnCount_(layout.columnCount),
          lineNumber_(prelude.linesBeforeData),
          // A PTS file with count lines only still needs room for the count.
          values_(layout.columnCount == 0 ? 1 : layout.usedColumns(), 0.0),
          positionColumn_(values_.size(), false) {
        for (const std::size_t column : layout.position) {
            positionColumn_[column] = column < positionColumn_.size();
        }
    }

    void parse(std::string_view text,
               const std::function<void(std::span<const double>, std::size_t)>& point);
    void finish() const {
        if (block_) {
            block_->check();
        }
    }
    /// 10^-d for the most decimals d of a coordinate parsed so far; 0 before the first point.
    double coordinateStep() const {
        return mostDecimals_ ? std::pow(10.0, -std::clamp(*mostDecimals_, -300, 300)) : 0.0;
    }

  private:
    /// Parses the values of one non-blank line from `p`, keeping the first values_.size();
    /// returns how many there are.
    std::size_t parseLine(const char* p, const char* end, std::string_view line,
                          std::size_t lineNumber);

    Separators separators_;
    bool pts_;
    std::size_t firstPointLine_;
    std::size_t columnCount_;
    std::size_t lineNumber_;
    std::vector<double> values_;
    std::vector<bool> positionColumn_;  // per kept value: whether it is x, y or z
    std::optional<int> mostDecimals_;   // of the coordinates (writtenDecimals)
    std::optional<PtsBlock> block_;
};

std::size_t PointLineParser::parseLine(const char* p, const char* end, std::string_view line,
                                       std::size_t lineNumber) {
    const char decimalPoint = separators_.decimalPoint();
    std::size_t count = 0;
    for (;;) {
        double value = 0.0;
        const char* next = parseValue(p, end, decimalPoint, value);
        if (next == nullptr ||
            (next != end && !isBlank(*next) && !separators_.isSeparator(*next))) {
            throwBadField(fieldAt(p, end, separators_), line, lineNumber);
        }
        if (count < values_.size()) {
            values_[count] = value;
            if (positionColumn_[count]) {
                mostDecimals_ = std::max(mostDecimals_.value_or(INT_MIN),
                                         writtenDecimals(p, next, decimalPoint));
            }
        }
        ++count;
        p = next;
        while (p != end && isBlank(*p)) {
            ++p;
        }
        if (p != end && separators_.isSeparator(*p)) {
            ++p;
            while (p != end && isBlank(*p)) {
                ++p;
            }
        }
        if (p == end) {
            return count;
        }
    }
}

void PointLineParser::parse(
    std::string_view text, const std::function<void(std::span<const double>, std::size_t)>& point) {
    LineReader lines(text, 0, lineNumber_);
    std::string_view line;
    while (lines.next(line)) {
        const char* p = line.data();
        const char* end = p + line.size();
        while (p != end && isBlank(*p)) {
            ++p;
        }
        if (p == end || *p == '#' || (*p == '/' && p + 1 != end && p[1] == '/')) {
            continue;
        }
        const std::size_t count = parseLine(p, end, line, lines.lineNumber());
        if (count == columnCount_) {
            point(values_, lines.lineNumber());
            if (block_) {
                ++block_->points;
            }
        } else if (pts_ && count == 1) {
            if (!isCount(values_[0])) {
                throwTooFewValues(count, lines.lineNumber());
            }
            finish();
            block_ = PtsBlock{lines.lineNumber(), static_cast<std::uint64_t>(values_[0]), 0};
        } else {
            throw Error(fmt::format("line {} has {}, but the first point (line {}) has {}",
                                    lines.lineNumber(), pluralValues(count), firstPointLine_,
                                    columnCount_));
        }
    }
    lineNumber_ = lines.lineNumber();
}

PointRecord makeRecord(const Layout& l, std::span<const double> values) {
    PointRecord record;
    record.position = {values[l.position[0]], values[l.position[1]], values[l.position[2]]};
    if (l.color) {
        const ColumnTriple& c = *l.color;
        record.color = {toColorChannel(values[c[0]], l.colorEncoding),
                        toColorChannel(values[c[1]], l.colorEncoding),
                        toColorChannel(values[c[2]], l.colorEncoding), 255};
    }
    if (l.normal) {
        const ColumnTriple& n = *l.normal;
        record.normal = {saturateToFloat(values[n[0]]), saturateToFloat(values[n[1]]),
                         saturateToFloat(values[n[2]])};
    }
    if (l.intensity) {
        record.intensity = saturateToFloat(values[*l.intensity]);
    }
    return record;
}

/// Printable text: no control characters but line ends and tabs. Bytes above 127 are allowed,
/// for UTF-8 column names.
bool isPrintableText(std::string_view text) {
    return std::all_of(text.begin(), text.end(), [](char c) {
        const auto byte = static_cast<unsigned char>(c);
        return byte >= 32 ? byte != 127 : isWhitespace(c);
    });
}

std::string_view withoutByteOrderMark(std::string_view text) {
    if (text.starts_with(kUtf8ByteOrderMark)) {
        text.remove_prefix(kUtf8ByteOrderMark.size());
    }
    return text;
}

std::string describeText(const Prelude& prelude, const Layout& layout) {
    std::string text = prelude.pts ? "PTS text" : "text";
    if (prelude.columnCount > 0) {
        text += ": " + describeLayout(layout);
    }
    if (prelude.sample.separators.decimalComma) {
        text += " (decimal commas)";
    }
    return text;
}

}  // namespace

TextColorEncoding TextColorRange::encoding() const {
    if (anyFraction_ && largest_ <= 1.0) {
        return ColorEncoding::UnitFloat;
    }
    if (largest_ > 255.0 && largest_ <= 65535.0) {
        return ColorEncoding::Word16;
    }
    return ColorEncoding::Byte;
}

struct PointTextReader::State {
    Prelude prelude;
    Layout layout;
    std::optional<PointLineParser> parser;
};

PointTextReader::PointTextReader(std::string_view head, ReadContext& context)
    : state_(std::make_unique<State>()) {
    if (head.starts_with("\xFF\xFE") || head.starts_with("\xFE\xFF")) {
        throw Error("it is UTF-16 text; save it as UTF-8 or ASCII");
    }
    if (head.substr(0, kSniffBytes).find('\0') != std::string_view::npos) {
        throw Error("it contains NUL bytes: it is binary data, not a text list of points");
    }
    const std::size_t start = head.starts_with(kUtf8ByteOrderMark) ? kUtf8ByteOrderMark.size() : 0;
    State& state = *state_;
    state.prelude = readPrelude(head, start);
    state.layout = chooseLayout(state.prelude, context.warnings);
    context.formatDetail = describeText(state.prelude, state.layout);
    state.parser.emplace(state.prelude, state.layout);
    // The sampled lines point into `head`, which the caller may now drop; only their number and
    // length (for expectedPoints) are kept.
    std::fill(state.prelude.sample.lines.begin(), state.prelude.sample.lines.end(),
              std::string_view{});
}

PointTextReader::~PointTextReader() = default;

const PointTextLayout& PointTextReader::layout() const {
    return state_->layout;
}

std::size_t PointTextReader::dataOffset() const {
    return state_->prelude.dataOffset;
}

/// Room for the points the text can hold, from the sampled line length: a count line or a
/// short first line must not make us reserve gigabytes.
std::size_t PointTextReader::expectedPoints(std::size_t bytes) const {
    const Sample& sample = state_->prelude.sample;
    if (sample.lines.empty()) {
        return 0;
    }
    // Every value takes at least a digit and a separator.
    const std::size_t atMost = bytes / (2 * state_->layout.columnCount);
    const double averageLine =
        static_cast<double>(sample.bytes) / static_cast<double>(sample.lines.size());
    // 10% more than the estimate, so slightly longer lines later need no second allocation.
    const double estimate = 1.1 * static_cast<double>(bytes) / averageLine;
    return static_cast<std::size_t>(
        std::min({estimate, static_cast<double>(atMost), static_cast<double>(kMaxPoints)}));
}

void PointTextReader::parse(
    std::string_view lines,
    const std::function<void(std::span<const double>, std::size_t)>& point) {
    state_->parser->parse(lines, point);
}

void PointTextReader::finish() const {
    state_->parser->finish();
}

double PointTextReader::coordinateStep() const {
    return state_->parser->coordinateStep();
}

void PointTextReader::restart(TextColorEncoding encoding, ReadContext& context) {
    State& state = *state_;
    state.layout.colorEncoding = encoding;
    context.formatDetail = describeText(state.prelude, state.layout);
    state.parser.emplace(state.prelude, state.layout);
}

namespace {

/// Parses the point lines of `text` into a cloud; `colors` sees every colour value.
PointCloud readPoints(std::string_view text, PointTextReader& reader, ReadContext& context,
                      TextColorRange& colors) {
    const Layout& layout = reader.layout();
    PointAttributes attributes;
    attributes.color = layout.color.has_value();
    attributes.normal = layout.normal.has_value();
    attributes.intensity = layout.intensity.has_value();
    PointCloudBuilder builder(attributes, reader.expectedPoints(text.size() - reader.dataOffset()));
    if (context.keepFilePrecision) {
        builder.keepPositionResiduals();
    }
    std::uint64_t pointLines = 0;
    // Whether a kept point's 16-bit colour is no 8-bit value times 257, which 8 bits lose.
    bool wordColorBeyondBytes = false;
    const auto addPoint = [&](std::span<const double> values, std::size_t) {
        if (layout.color) {
            for (const std::size_t column : *layout.color) {
                colors.add(values[column]);
            }
        }
        const std::size_t kept = builder.validPoints();
        builder.add(makeRecord(layout, values));
        if (layout.color && layout.colorEncoding == ColorEncoding::Word16 &&
            builder.validPoints() > kept) {
            for (const std::size_t column : *layout.color) {
                wordColorBeyondBytes =
                    wordColorBeyondBytes || colorWordNeedsSixteenBits(values[column]);
            }
        }
        if (++pointLines > kMaxPoints) {
            throw Error(fmt::format("it has more than the {} points subscan can hold", kMaxPoints));
        }
    };
    // Pieces of whole lines, so that progress is reported between them.
    for (std::size_t position = reader.dataOffset(); position < text.size();) {
        const std::size_t lineEnd =
            text.find('\n', std::min(text.size(), position + kProgressBytes));
        const std::size_t end = lineEnd == std::string_view::npos ? text.size() : lineEnd + 1;
        reader.parse(text.substr(position, end - position), addPoint);
        context.reportProgress(end, text.size());
        position = end;
    }
    reader.finish();
    PointCloud cloud = builder.finish(context.warnings);
    cloud.coordinateStep = reader.coordinateStep();
    cloud.colorCutTo8Bits = wordColorBeyondBytes;
    return cloud;
}

}  // namespace

PointCloud readXyz(std::span<const std::byte> file, ReadContext& context) {
    const std::string_view text(reinterpret_cast<const char*>(file.data()), file.size());
    PointTextReader reader(text, context);
    const std::size_t layoutWarnings = context.warnings.size();
    TextColorRange colors;
    PointCloud cloud = readPoints(text, reader, context, colors);
    const Layout& layout = reader.layout();
    if (layout.color && !layout.colorEncodingFromName &&
        colors.encoding() != layout.colorEncoding) {
        // The first lines misled the guess. Reading the file again costs no memory, which
        // keeping every point's colour values until the end would; such files are rare.
        cloud = PointCloud{};
        context.warnings.resize(layoutWarnings);
        reader.restart(colors.encoding(), context);
        cloud = readPoints(text, reader, context, colors);
    }
    return cloud;
}

bool looksLikePointText(std::span<const std::byte> file) {
    const std::string_view whole(reinterpret_cast<const char*>(file.data()), file.size());
    const std::string_view text = withoutByteOrderMark(whole.substr(0, kSniffBytes));
    const bool complete = whole.size() <= kSniffBytes;
    if (!isPrintableText(text)) {
        return false;
    }
    LineReader lines(text, 0, 0);
    std::string_view line;
    while (lines.next(line)) {
        const bool cut = !complete && !lines.terminated();
        const std::string_view content = trimBlanks(line);
        if (content.empty() || isComment(content)) {
            continue;
        }
        if (startsWithWord(content, Separators{})) {
            continue;  // a header line
        }
        std::vector<std::string_view> fields;
        FieldScanner scanner(content, Separators{});
        while (const auto field = scanner.next()) {
            fields.push_back(*field);
        }
        if (cut && !fields.empty() && !isNumber(fields.back(), Separators{})) {
            fields.pop_back();  // the window ends inside this number, e.g. after "1.5e"
        }
        if (!std::all_of(fields.begin(), fields.end(),
                         [](std::string_view field) { return isNumber(field, Separators{}); })) {
            return false;
        }
        if (fields.size() == 1 && !cut) {
            continue;  // a PTS count line
        }
        return fields.size() >= 3;
    }
    return false;
}

}  // namespace subscan
