#include "io/PointRecordSource.h"

namespace subscan {

std::size_t PointRecordFormat::recordLength() const {
    constexpr std::size_t kStandardLength[] = {30, 36, 38};  // formats 6, 7, 8
    return kStandardLength[pointFormat - 6] + extraBytes;
}

}  // namespace subscan
