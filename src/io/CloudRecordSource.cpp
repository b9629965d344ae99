#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/RecordSourceSupport.h"
#include "io/ScanLoader.h"

// Inputs read whole (ASCII PLY, PCD, E57, OFF, synthetic:NAME) as records: the cloud's
// positions are its origin plus float offsets, quantized like writeLas quantizes them; colour,
// normals, intensity and classification are kept.
namespace subscan {

namespace {

class CloudRecordSource final : public PointRecordSource {
  public:
    explicit CloudRecordSource(const std::string& source) {
        LoadedScan scan = loadScan(source);
        start(std::move(scan.cloud), source);
        for (const std::string& warning : scan.warnings) {
            info_.warnings.push_back(fmt::format("{}: {}", source, warning));
        }
    }
    CloudRecordSource(PointCloud cloud, const std::string& name) { start(std::move(cloud), name); }

    const PointRecordSourceInfo& info() const override { return info_; }

    std::size_t read(std::vector<std::byte>& records, std::size_t maxPoints) override {
        const std::size_t count = std::min(maxPoints, cloud_.size() - next_);
        records.reserve(records.size() + count * info_.format.recordLength());
        for (std::size_t i = next_; i < next_ + count; ++i) {
            ConvertedPoint point;
            point.position = cloud_.fileCoordinates(i);
            if (cloud_.hasColors()) {
                const Rgba8& color = cloud_.colors[i];
                point.rgb = {colorWordFromByte(color.r), colorWordFromByte(color.g),
                             colorWordFromByte(color.b)};
            }
            if (cloud_.hasNormals()) {
                point.normal = cloud_.normals[i];
            }
            if (cloud_.hasIntensities()) {
                point.intensity = intensityWord(cloud_.intensities[i]);
            }
            if (cloud_.hasClassifications()) {
                point.classification = cloud_.classifications[i];
            }
            writer_->append(records, point);
        }
        next_ += count;
        return count;
    }

    void rewind() override { next_ = 0; }

  private:
    void start(PointCloud cloud, const std::string& source) {
        cloud_ = std::move(cloud);
        Bounds bounds;
        for (std::size_t i = 0; i < cloud_.size(); ++i) {
            bounds.add(cloud_.fileCoordinates(i));
        }
        try {
            writer_.emplace(cloud_.hasColors(), cloud_.hasNormals(), bounds);
        } catch (const Error& error) {
            throwNamed(source, error);
        }
        info_ = convertedSourceInfo(source, cloud_.size(), *writer_, bounds);
        if (!cloud_.triangles.empty()) {
            info_.warnings.push_back(facesNotKept(source, cloud_.triangles.size()));
            cloud_.triangles = {};
        }
        if (!fitIntensityWords(cloud_.intensities)) {
            info_.warnings.push_back(intensitiesNotKept(source));
        }
    }

    PointCloud cloud_;
    std::optional<ConvertedRecordWriter> writer_;
    PointRecordSourceInfo info_;
    std::size_t next_ = 0;
};

}  // namespace

std::unique_ptr<PointRecordSource> openCloudRecordSource(const std::string& source) {
    return std::make_unique<CloudRecordSource>(source);
}

std::unique_ptr<PointRecordSource> cloudRecordSource(PointCloud cloud, const std::string& name) {
    return std::make_unique<CloudRecordSource>(std::move(cloud), name);
}

}  // namespace subscan
