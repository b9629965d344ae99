#include "io/XyzReader.h"

#include "core/Error.h"

namespace subscan {

PointCloud readXyz(std::span<const std::byte>, ReadContext&) {
    throw Error("Xyz reading is being written");
}

}  // namespace subscan

namespace subscan {
bool looksLikePointText(std::span<const std::byte>) {
    return false;
}
}  // namespace subscan
