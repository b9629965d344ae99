#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "io/AtomicFile.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

std::string contents(const std::filesystem::path& path) {
    std::ifstream stream(path, std::ios::binary);
    std::ostringstream out;
    out << stream.rdbuf();
    return out.str();
}

std::size_t fileCount(const std::filesystem::path& directory) {
    return static_cast<std::size_t>(std::distance(std::filesystem::directory_iterator(directory),
                                                  std::filesystem::directory_iterator()));
}

TEST(AtomicFileTest, WritesAndReplaces) {
    const test::TempDir dir;
    const auto path = dir / "out.bin";
    writeFileAtomically(path, "first");
    writeFileAtomically(path, "second");
    EXPECT_EQ(contents(path), "second");
    EXPECT_EQ(fileCount(dir.path()), 1u);  // no temporary left behind
}

TEST(AtomicFileTest, FailureLeavesTheOldFileAndNoTemporary) {
    const test::TempDir dir;
    const auto path = dir.write("out.bin", "old");
    EXPECT_THROW(writeFileAtomically(path,
                                     [](std::ostream& stream) {
                                         stream << "partial";
                                         throw std::runtime_error("encoder failed");
                                     }),
                 std::runtime_error);
    EXPECT_EQ(contents(path), "old");
    EXPECT_EQ(fileCount(dir.path()), 1u);
}

TEST(AtomicFileTest, AFailedRenameLeavesTheTargetAndNoTemporary) {
    // A non-empty directory where the file should go: the content is written, the rename fails.
    const test::TempDir dir;
    const auto path = dir / "out.bin";
    std::filesystem::create_directory(path);
    const auto inside = dir.write("out.bin/kept.txt", "kept");
    try {
        writeFileAtomically(path, "new");
        FAIL() << "no error";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), ::testing::HasSubstr("cannot replace the file"));
        EXPECT_THAT(error.what(), ::testing::HasSubstr(path.string()));
    }
    EXPECT_EQ(contents(inside), "kept");
    EXPECT_EQ(fileCount(dir.path()), 1u);
}

TEST(AtomicFileTest, MissingDirectoryIsAClearError) {
    const test::TempDir dir;
    try {
        writeFileAtomically(dir / "nowhere" / "out.png", "x");
        FAIL() << "no error";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), ::testing::HasSubstr("does not exist"));
    }
}

TEST(AtomicFileTest, ATemporaryFileNamesItsTarget) {
    // A process killed while writing leaves its temporary file: turntable removes those in its
    // own staging folders by the names of the files they were to become.
    const test::TempDir dir;
    std::string temporary;
    writeFileAtomically(dir / "0003.png", [&](std::ostream& stream) {
        temporary = test::folderEntries(dir.path()).at(0);
        stream << "frame";
    });
    EXPECT_EQ(atomicWriteTargetOf(temporary), "0003.png");
    for (const char* other :
         {"0003.png", ".0003.png.tmp", ".0003.png.0123ABCD.tmp", "..0123abcd.tmp",
          ".0003.png-0123abcd.tmp", "0003.png.0123abcd.tmp"}) {
        EXPECT_EQ(atomicWriteTargetOf(other), std::nullopt) << other;
    }
}

}  // namespace
}  // namespace subscan
