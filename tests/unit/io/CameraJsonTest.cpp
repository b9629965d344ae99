#include <string>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "io/CameraJson.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

TEST(CameraJsonTest, RoundTripsAndWritesRowMajorMatrices) {
    Camera camera;
    camera.width = 320;
    camera.height = 200;
    camera.fovyDegrees = 37.5;
    camera.nearPlane = 0.25;
    camera.farPlane = 80;
    camera.view = glm::lookAt(glm::dvec3(500001.5, 5400002.25, 30), glm::dvec3(500000, 5400000, 0),
                              glm::dvec3(0, 0, 1));
    const nlohmann::json json = cameraToJson(camera);
    // Row-major: the translation sits in the last column of the first three rows.
    EXPECT_EQ(json["view"][0][3].get<double>(), camera.view[3][0]);
    EXPECT_EQ(json["projection"][3][2].get<double>(), -1.0);
    const test::TempDir dir;
    writeCameraFile(dir / "camera.json", camera);
    const Camera back = readCameraFile(dir / "camera.json");
    EXPECT_EQ(back.width, 320);
    EXPECT_EQ(back.height, 200);
    EXPECT_EQ(back.fovyDegrees, 37.5);
    EXPECT_EQ(back.nearPlane, 0.25);
    EXPECT_EQ(back.farPlane, 80);
    EXPECT_EQ(back.view, camera.view);             // JSON numbers round-trip doubles exactly
    EXPECT_FALSE(json.contains("jitter_pixels"));  // written only for a jittered camera

    camera.jitterPixels = {0.25, -0.375};
    const nlohmann::json jittered = cameraToJson(camera);
    EXPECT_EQ(cameraFromJson(jittered).jitterPixels, camera.jitterPixels);
    // The projection holds the shift: x by 2 * 0.25 / 320 in clip space per unit of w.
    EXPECT_NEAR(jittered["projection"][0][3].get<double>() - json["projection"][0][3].get<double>(),
                0.0, 1e-15);
    EXPECT_NEAR(jittered["projection"][0][2].get<double>() - json["projection"][0][2].get<double>(),
                -2.0 * 0.25 / 320, 1e-15);
    nlohmann::json bad = jittered;
    bad["jitter_pixels"] = {0.1};
    EXPECT_THROW(cameraFromJson(bad), Error);

    // A sensor's principal point off the middle: kept apart from the jitter, shifting the
    // projection by both (y down in pixels is up in clip space).
    camera.principalOffsetPixels = {4.0, -16.0};
    const nlohmann::json sensor = cameraToJson(camera);
    const Camera sensorBack = cameraFromJson(sensor);
    EXPECT_EQ(sensorBack.principalOffsetPixels, camera.principalOffsetPixels);
    EXPECT_EQ(sensorBack.jitterPixels, camera.jitterPixels);
    EXPECT_NEAR(sensor["projection"][0][2].get<double>() - json["projection"][0][2].get<double>(),
                -2.0 * (0.25 + 4.0) / 320, 1e-15);
    EXPECT_NEAR(sensor["projection"][1][2].get<double>() - json["projection"][1][2].get<double>(),
                2.0 * (-0.375 - 16.0) / 200, 1e-15);
    bad = sensor;
    bad["principal_offset_pixels"] = {1.0, "x"};
    try {
        cameraFromJson(bad);
        FAIL() << "accepted a principal offset that is not 2 numbers";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), ::testing::HasSubstr("principal_offset_pixels"));
    }
}

TEST(CameraJsonTest, InvalidFieldsAreNamed) {
    const nlohmann::json valid = cameraToJson(Camera{});
    struct Case {
        const char* key;
        nlohmann::json value;
        const char* message;
    };
    const Case cases[] = {
        {"width", 0, "outside 1..65536"},
        {"height", "tall", "'height' has the wrong type"},
        {"fovy_deg", 180, "fovy_deg"},
        {"near", -1, "0 < near < far"},
        {"far", 0.001, "0 < near < far"},
        {"view", nlohmann::json::array({nlohmann::json::array({1, 2, 3, 4})}),
         "4 rows of 4 numbers"},
        {"view", nlohmann::json::array({1, 2}), "'view' has the wrong type"},
    };
    for (const Case& c : cases) {
        nlohmann::json json = valid;
        json[c.key] = c.value;
        try {
            cameraFromJson(json);
            ADD_FAILURE() << c.key << " accepted";
        } catch (const Error& error) {
            EXPECT_THAT(error.what(), HasSubstr(c.message)) << c.key;
        }
    }
    nlohmann::json missing = valid;
    missing.erase("view");
    EXPECT_THROW(cameraFromJson(missing), Error);
}

TEST(CameraJsonTest, AViewThatIsNoRigidMotionOrAnotherProjectionIsRefused) {
    // Both used to be drawn: a scaled view as a stretched picture, a projection that disagrees
    // with fovy_deg (another tool's, an orthographic one) as if it were not there.
    Camera camera;
    camera.view = glm::lookAt(glm::dvec3(1, 2, 5), glm::dvec3(0), glm::dvec3(0, 1, 0));
    const nlohmann::json valid = cameraToJson(camera);
    EXPECT_NO_THROW(cameraFromJson(valid));
    nlohmann::json withoutProjection = valid;
    withoutProjection.erase("projection");
    EXPECT_NO_THROW(cameraFromJson(withoutProjection));
    // Printed with 4 decimals, as numpy's or MATLAB's short formats write it: accepted. So is a
    // size written as a float (1280.0).
    nlohmann::json rounded = valid;
    for (const char* key : {"view", "projection"}) {
        for (auto& row : rounded[key]) {
            for (auto& value : row) {
                value = std::stod(fmt::format("{:.4f}", value.get<double>()));
            }
        }
    }
    rounded["width"] = valid["width"].get<double>();
    ASSERT_TRUE(rounded["width"].is_number_float());
    EXPECT_NO_THROW(cameraFromJson(rounded));
    EXPECT_EQ(cameraFromJson(rounded).width, camera.width);

    auto expectRefused = [](const nlohmann::json& json, const char* message, const char* what) {
        try {
            cameraFromJson(json);
            ADD_FAILURE() << what << " accepted";
        } catch (const Error& error) {
            EXPECT_THAT(error.what(), HasSubstr(message)) << what;
        }
    };
    nlohmann::json scaled = valid;
    for (int column = 0; column < 3; ++column) {  // 1 % wider, a picture visibly stretched
        scaled["view"][0][column] = 1.01 * scaled["view"][0][column].get<double>();
    }
    expectRefused(scaled, "not a rigid motion", "a scaled view");
    nlohmann::json zeroRow = valid;
    zeroRow["view"][0] = {0, 0, 0, 0};
    expectRefused(zeroRow, "not a rigid motion", "a zero row");
    nlohmann::json projective = valid;
    projective["view"][3] = {0, 0, 1, 0};
    expectRefused(projective, "not a rigid motion", "a projective last row");
    nlohmann::json mirrored = valid;
    for (int column = 0; column < 4; ++column) {
        mirrored["view"][2][column] = -mirrored["view"][2][column].get<double>();
    }
    expectRefused(mirrored, "not a rigid motion", "a mirrored view");
    nlohmann::json wider = valid;
    wider["projection"][0][0] = 5.0;
    expectRefused(wider, "'projection' is not the one", "another projection");
    nlohmann::json edited = valid;
    edited["fovy_deg"] = 60.0;  // the projection left as it was
    expectRefused(edited, "'projection' is not the one", "fovy_deg edited alone");
    nlohmann::json fractional = valid;
    fractional["width"] = 33.5;
    expectRefused(fractional, "'width' 33.5 is not a whole number", "a fractional width");
}

TEST(CameraJsonTest, ANumberBeyondADoubleIsNamedWithTheFile) {
    // The parser reports 1e999 as an error of another kind than bad JSON: it ended the command
    // as an "internal error" without the file's name.
    const test::TempDir dir;
    const auto file = dir.write("camera.json", R"({"fovy_deg": 1e999})");
    try {
        readCameraFile(file);
        ADD_FAILURE() << "1e999 accepted";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), HasSubstr("camera.json: not valid JSON: a number beyond"));
    }
}

}  // namespace
}  // namespace subscan
