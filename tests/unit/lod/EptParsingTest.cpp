// The EPT parsers (ept.json and hierarchy pages) on text written here: what PDAL's lone star
// copy holds, and each way such text can be wrong.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "lod/NodeSource.h"
#include "support/TestSupport.h"

namespace subscan::lod {
namespace {

using ::testing::HasSubstr;

constexpr const char* kDescription =
    R"({"bounds": [515363, 4918339, 2309, 515407, 4918383, 2353],
        "boundsConforming": [515368, 4918340, 2322, 515402, 4918382, 2339],
        "dataType": "laszip", "hierarchyType": "json", "points": 518862, "span": 128,
        "version": "1.0.0"})";

TEST(EptParsingTest, TheDescriptionGivesTheCubeSpacingAndBounds) {
    const EptDescription ept = parseEptDescription(kDescription);
    EXPECT_DOUBLE_EQ(ept.cube.halfSize, 22.0);
    EXPECT_DOUBLE_EQ(ept.cube.center.x, 515385.0);
    EXPECT_DOUBLE_EQ(ept.cube.center.z, 2331.0);
    EXPECT_DOUBLE_EQ(ept.cube.rootSpacing, 44.0 / 128.0);  // the cube's side over its span
    EXPECT_DOUBLE_EQ(ept.bounds.min.y, 4918340.0);
    EXPECT_DOUBLE_EQ(ept.bounds.max.z, 2339.0);
    EXPECT_EQ(ept.points, 518862u);
    EXPECT_EQ(ept.version, "1.0.0");
}

TEST(EptParsingTest, WhatIsNotAnEptDescriptionIsOneSentence) {
    const auto refusal = [](const std::string& text) {
        return test::errorMessage([&] { parseEptDescription(text); });
    };
    EXPECT_EQ(refusal("{\"bounds\": ["), "is not valid JSON");
    EXPECT_THAT(refusal(R"({"dataType": "binary", "bounds": [0,0,0,1,1,1], "span": 8})"),
                HasSubstr("holds \"binary\" tiles; subscan reads EPT with LAZ tiles"));
    EXPECT_THAT(refusal(R"({"dataType": "zstandard"})"), HasSubstr("\"zstandard\" tiles"));
    EXPECT_THAT(refusal(R"({"dataType": "laszip", "hierarchyType": "gzip"})"),
                HasSubstr("\"gzip\" hierarchy"));
    EXPECT_THAT(refusal(R"({"dataType": "laszip", "bounds": [0,0,0,2,1,1], "span": 8,
                            "points": 1})"),
                HasSubstr("not a cube"));
    EXPECT_THAT(refusal(R"({"dataType": "laszip", "bounds": [0,0,0,1e300,1e300,1e300],
                            "span": 8, "points": 1})"),
                HasSubstr("not 6 coordinates"));
    EXPECT_THAT(refusal(R"({"dataType": "laszip", "bounds": [0,0,0,1,1,1], "span": 0,
                            "points": 1})"),
                HasSubstr("\"span\" outside 1 to 1e9"));
    EXPECT_THAT(refusal(R"({"dataType": "laszip", "bounds": [0,0,0,1,1,1], "span": 8})"),
                HasSubstr("is not an EPT description"));  // no "points"
}

TEST(EptParsingTest, APageListsNodesAndPointsToPages) {
    const EptHierarchyPage page =
        parseEptHierarchyPage(R"({"0-0-0-0": 41998, "1-1-1-1": 48879, "2-2-2-1": -1,
                                  "3-5-4-3": 0})");
    ASSERT_EQ(page.nodes.size(), 2u);
    EXPECT_EQ(page.nodes[0].key.level, 0);
    EXPECT_EQ(page.nodes[0].pointCount, 41998u);
    EXPECT_EQ(page.nodes[1].key.x, 1);
    EXPECT_EQ(page.nodes[1].pointCount, 48879u);
    ASSERT_EQ(page.pages.size(), 1u);  // a node without points is no node
    EXPECT_EQ(page.pages[0].level, 2);
    EXPECT_EQ(page.pages[0].z, 1);
}

TEST(EptParsingTest, WhatIsNotAPageIsOneSentence) {
    const auto refusal = [](const std::string& text) {
        return test::errorMessage([&] { parseEptHierarchyPage(text); });
    };
    EXPECT_EQ(refusal("[1, 2]"), "is not an EPT hierarchy (a JSON object)");
    for (const char* key : {"0-0-0", "0-0-0-0-0", "a-0-0-0", "99999999999-0-0-0", "0-0-0-0 "}) {
        SCOPED_TRACE(key);
        EXPECT_THAT(refusal(std::string("{\"") + key + "\": 5}"),
                    HasSubstr("is not a key D-X-Y-Z with a count"));
    }
    EXPECT_THAT(refusal(R"({"0-0-0-0": 2.5})"), HasSubstr("is not a key D-X-Y-Z with a count"));
    EXPECT_EQ(refusal(R"({"0-0-0-0": -2})"), "the entry \"0-0-0-0\" has a count of -2");
}

}  // namespace
}  // namespace subscan::lod
