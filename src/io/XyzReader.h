#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string_view>

#include "core/PointCloud.h"
#include "io/ReadContext.h"

namespace subscan {

/// Reads a text list of points held in memory (XYZ, PTS, TXT, CSV): one point per line, values
/// separated by whitespace, commas or semicolons; `x y z`, `x y z i`, `x y z r g b`,
/// `x y z i r g b` (PTS, after its count line) and a few more layouts; leading header lines are
/// skipped (and used to name the columns when they can). Throws subscan::Error.
PointCloud readXyz(std::span<const std::byte> file, ReadContext& context);

/// True when the start of `file` reads as lines of numbers, for files without a telling extension.
bool looksLikePointText(std::span<const std::byte> file);

/// How the colour columns of a point text are written: bytes, 0..1 floats or 16-bit values.
enum class TextColorEncoding { Byte, UnitFloat, Word16 };

/// The encoding that fits colour values: fractions no larger than 1 are 0..1 floats, values
/// above 255 (up to 65535) are 16-bit, as PDAL writes LAS colour; anything else is bytes. Only
/// every value of a file tells: a scan that starts in the dark has 16-bit colours below 256 on
/// its first lines.
class TextColorRange {
  public:
    void add(double value) {
        if (!std::isnan(value)) {
            largest_ = std::max(largest_, value);
            anyFraction_ = anyFraction_ || value != std::floor(value);
        }
    }
    TextColorEncoding encoding() const;

  private:
    double largest_ = 0.0;
    bool anyFraction_ = false;
};

/// Which column of a point line holds what.
struct PointTextLayout {
    std::size_t columnCount = 0;  // values on a point line; 0 in a PTS file of count lines only
    std::array<std::size_t, 3> position{0, 1, 2};
    std::optional<std::array<std::size_t, 3>> color;
    TextColorEncoding colorEncoding = TextColorEncoding::Byte;
    bool colorEncodingFromName = false;  // rf gf bf: no need to look at the values
    std::optional<std::array<std::size_t, 3>> normal;
    std::optional<std::size_t> intensity;

    /// How many leading values of a line the layout reads.
    std::size_t usedColumns() const {
        std::size_t last = std::max({position[0], position[1], position[2]});
        if (color) {
            last = std::max({last, (*color)[0], (*color)[1], (*color)[2]});
        }
        if (normal) {
            last = std::max({last, (*normal)[0], (*normal)[1], (*normal)[2]});
        }
        if (intensity) {
            last = std::max(last, *intensity);
        }
        return last + 1;
    }
};

/// A text list of points read in pieces: the layout is decided from the file's first lines (the
/// header lines and a sample of point lines), then the point lines are parsed piece by piece,
/// so a file of any size goes through a buffer of bounded size. The sample's colour encoding is
/// a first guess; callers judge it from every value with TextColorRange. readXyz is this reader
/// given the whole file.
class PointTextReader {
  public:
    /// `head` is the start of the file: all of it, or whole lines enough to hold the lines
    /// before the points and the first hundred point lines. Throws subscan::Error when it is
    /// not a list of points; layout warnings and the format detail go to `context`.
    PointTextReader(std::string_view head, ReadContext& context);
    ~PointTextReader();
    PointTextReader(const PointTextReader&) = delete;
    PointTextReader& operator=(const PointTextReader&) = delete;

    const PointTextLayout& layout() const;
    /// The file offset of the first point line (or PTS count line).
    std::size_t dataOffset() const;
    /// A generous estimate of the points in `bytes` of point lines, from the sampled lines.
    std::size_t expectedPoints(std::size_t bytes) const;

    /// Parses `lines`, the file's next whole lines from dataOffset() on (only the file's last
    /// line may lack its line end). `point` receives the values of each point line, at least
    /// layout().usedColumns() of them, and the line's number. Throws subscan::Error, naming the
    /// line, at a line that is neither a point nor a PTS count.
    void parse(std::string_view lines,
               const std::function<void(std::span<const double>, std::size_t)>& point);
    /// At the end of the file: checks the point count of the last PTS block.
    void finish() const;
    /// The step of the decimal grid the coordinates parsed so far are written on: 10^-d for the
    /// most decimals d of any of them (a number's exponent counts: 1.5e3 has -2); 0 before the
    /// first point. Text keeps what its writer wrote, so this is the precision it carries.
    double coordinateStep() const;
    /// Starts again at dataOffset(), with the colour columns read as `encoding`: for a file
    /// whose later lines showed that the first ones misled the guess. The format detail in
    /// `context` says so.
    void restart(TextColorEncoding encoding, ReadContext& context);

  private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace subscan
