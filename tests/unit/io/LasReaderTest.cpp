#include <gtest/gtest.h>

TEST(LasReaderTest, BeingWritten) {
    GTEST_SKIP() << "the Las reader tests are being written";
}
