#include "io/LasReader.h"

#include "core/Error.h"

namespace subscan {

PointCloud readLas(std::span<const std::byte>, ReadContext&) {
    throw Error("Las reading is being written");
}

}  // namespace subscan
