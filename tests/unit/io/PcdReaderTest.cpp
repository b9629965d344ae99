#include <gtest/gtest.h>

TEST(PcdReaderTest, BeingWritten) {
    GTEST_SKIP() << "the Pcd reader tests are being written";
}
