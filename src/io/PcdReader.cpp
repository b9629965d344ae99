#include "io/PcdReader.h"

#include "core/Error.h"

namespace subscan {

PointCloud readPcd(std::span<const std::byte>, ReadContext&) {
    throw Error("Pcd reading is being written");
}

}  // namespace subscan
