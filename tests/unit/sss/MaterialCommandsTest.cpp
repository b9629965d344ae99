#include <algorithm>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "sss/MaterialLibrary.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::runSubscan;
using ::testing::HasSubstr;
using ::testing::UnorderedElementsAre;

std::vector<std::string> keysOf(const nlohmann::json& object) {
    std::vector<std::string> keys;
    for (const auto& [key, value] : object.items()) {
        keys.push_back(key);
    }
    return keys;
}

TEST(MaterialCommandsTest, MaterialsJsonListsTheLibrary) {
    const test::CommandResult result = runSubscan({"materials", "--json"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const nlohmann::json materials = nlohmann::json::parse(result.out);
    ASSERT_TRUE(materials.is_array());
    ASSERT_EQ(materials.size(), materialLibrary().size());
    for (const nlohmann::json& material : materials) {
        EXPECT_THAT(keysOf(material),
                    UnorderedElementsAre("name", "description", "eta", "sigma_s_prime", "sigma_a",
                                         "rd", "cumulative", "gaussians"));
        for (const nlohmann::json& term : material["gaussians"]) {
            EXPECT_THAT(keysOf(term), UnorderedElementsAre("variance_mm2", "weight"));
            EXPECT_EQ(term["weight"].size(), 3u);
        }
    }
    // The JSON carries the library's numbers exactly, and null where there are none.
    const auto find = [&](const std::string& name) {
        return *std::find_if(materials.begin(), materials.end(),
                             [&](const nlohmann::json& m) { return m["name"] == name; });
    };
    const nlohmann::json skin1 = find("skin1");
    EXPECT_EQ(skin1["sigma_a"].get<Rgb>(), *findMaterial("skin1").sigmaA);
    EXPECT_EQ(skin1["gaussians"][2]["variance_mm2"].get<double>(),
              findMaterial("skin1").gaussians.gaussians[2].varianceMm2);
    EXPECT_EQ(skin1["cumulative"], false);
    const nlohmann::json jimenez = find("skin-jimenez");
    EXPECT_TRUE(jimenez["sigma_s_prime"].is_null());
    EXPECT_TRUE(jimenez["rd"].is_null());
    EXPECT_EQ(jimenez["cumulative"], true);
    EXPECT_EQ(jimenez["gaussians"][0]["variance_mm2"], 0.0);
}

TEST(MaterialCommandsTest, MaterialsTableHasALinePerMaterial) {
    const test::CommandResult result = runSubscan({"materials"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_THAT(result.out, HasSubstr("wholemilk"));
    EXPECT_THAT(result.out, HasSubstr("marble-jimenez"));
    // A header, the materials, a blank line and a hint.
    EXPECT_EQ(test::lineCount(result.out), materialLibrary().size() + 3);
}

TEST(MaterialCommandsTest, FitProfileJson) {
    const test::CommandResult result =
        runSubscan({"fit-profile", "--material", "skin2", "--gaussians", "3", "--json"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const nlohmann::json fit = nlohmann::json::parse(result.out);
    EXPECT_THAT(keysOf(fit),
                UnorderedElementsAre("material", "gaussians", "fit_error", "r_max_mm"));
    EXPECT_EQ(fit["material"], "skin2");
    ASSERT_EQ(fit["gaussians"].size(), 3u);
    for (const nlohmann::json& term : fit["gaussians"]) {
        EXPECT_THAT(keysOf(term), UnorderedElementsAre("variance_mm2", "weight"));
    }
    EXPECT_EQ(fit["fit_error"].size(), 3u);
    EXPECT_GT(fit["r_max_mm"].get<double>(), 0.0);
}

TEST(MaterialCommandsTest, FitProfileBurleyAndTable) {
    const test::CommandResult result = runSubscan(
        {"fit-profile", "--material", "apple", "--gaussians", "2", "--profile", "burley"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_THAT(result.out, HasSubstr("Burley"));
    EXPECT_THAT(result.out, HasSubstr("fit error"));
}

TEST(MaterialCommandsTest, FitProfileErrorsAreOneSentence) {
    const test::CommandResult unknown =
        runSubscan({"fit-profile", "--material", "jade", "--gaussians", "4"});
    EXPECT_EQ(unknown.exitCode, 1);
    EXPECT_TRUE(unknown.out.empty());
    EXPECT_EQ(test::lineCount(unknown.err), 1u) << unknown.err;
    EXPECT_THAT(unknown.err, HasSubstr("there is no material 'jade'"));

    const test::CommandResult gaussianOnly =
        runSubscan({"fit-profile", "--material", "skin-deon", "--gaussians", "4"});
    EXPECT_EQ(gaussianOnly.exitCode, 1);
    EXPECT_EQ(test::lineCount(gaussianOnly.err), 1u) << gaussianOnly.err;
    EXPECT_THAT(gaussianOnly.err, HasSubstr("'skin-deon'"));
    EXPECT_THAT(gaussianOnly.err, HasSubstr("no diffusion profile"));
}

TEST(MaterialCommandsTest, FitProfileUsageErrorsExitWithTwo) {
    EXPECT_EQ(runSubscan({"fit-profile", "--material", "skin1", "--gaussians", "0"}).exitCode, 2);
    EXPECT_EQ(runSubscan({"fit-profile", "--material", "skin1", "--gaussians", "13"}).exitCode, 2);
    EXPECT_EQ(runSubscan({"fit-profile", "--material", "skin1", "--gaussians", "x"}).exitCode, 2);
    EXPECT_EQ(runSubscan({"fit-profile", "--material", "skin1"}).exitCode, 2);
    EXPECT_EQ(runSubscan({"fit-profile", "--gaussians", "4"}).exitCode, 2);
    EXPECT_EQ(runSubscan({"fit-profile", "--material", "skin1", "--gaussians", "4", "--profile",
                          "gaussian"})
                  .exitCode,
              2);
    EXPECT_EQ(runSubscan({"materials", "--frobnicate"}).exitCode, 2);
}

}  // namespace
}  // namespace subscan
