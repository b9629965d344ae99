#include <gtest/gtest.h>

TEST(XyzReaderTest, BeingWritten) {
    GTEST_SKIP() << "the Xyz reader tests are being written";
}
