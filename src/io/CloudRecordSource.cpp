#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/RecordSourceSupport.h"
#include "io/ScanLoader.h"

// Inputs read whole (ASCII PLY, PCD, E57, OFF, synthetic:NAME) as records: the cloud's
// positions are its file coordinates (origin, float offsets and their residuals where kept),
// quantized like writeLas quantizes them; colour,
// normals, intensity and classification are kept.
namespace subscan {

namespace {

class CloudRecordSource final : public ConvertedRecordSource {
  public:
    explicit CloudRecordSource(const std::string& source) {
        // Records are quantized from the file's coordinates, not from the floats drawn.
        LoadedScan scan = loadScan(source, {}, /*keepFilePrecision=*/true);
        std::vector<std::string> warnings;
        for (const std::string& warning : scan.warnings) {
            warnings.push_back(fmt::format("{}: {}", source, warning));
        }
        start(std::move(scan.cloud), source, std::move(warnings));
    }
    CloudRecordSource(PointCloud cloud, const std::string& name) {
        start(std::move(cloud), name, {});
    }

    std::size_t read(std::vector<std::byte>& records, std::size_t maxPoints) override {
        const std::size_t count = std::min(maxPoints, cloud_.size() - next_);
        records.reserve(records.size() + count * info().format.recordLength());
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
            writer().append(records, point);
        }
        next_ += count;
        return count;
    }

    void rewind() override { next_ = 0; }

  private:
    void start(PointCloud cloud, const std::string& source, std::vector<std::string> warnings) {
        cloud_ = std::move(cloud);
        Bounds bounds;
        for (std::size_t i = 0; i < cloud_.size(); ++i) {
            bounds.add(cloud_.fileCoordinates(i));
        }
        if (!cloud_.triangles.empty()) {
            warnings.push_back(facesNotKept(source, cloud_.triangles.size()));
            cloud_.triangles = {};
        }
        if (!fitIntensityWords(cloud_.intensities)) {
            warnings.push_back(intensitiesNotKept(source));
        }
        // The cloud holds 8-bit colour; records of an input loaded whole can carry no more.
        if (cloud_.colorCutTo8Bits) {
            warnings.push_back(fmt::format(
                "{}: colour of more than 8 bits a channel is cut to 8 bits (the input is loaded "
                "whole, as 8-bit colour)",
                source));
        }
        startRecords(source, cloud_.size(), cloud_.hasColors(), cloud_.hasNormals(), bounds,
                     cloud_.coordinateStep, std::move(warnings));
    }

    PointCloud cloud_;
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
