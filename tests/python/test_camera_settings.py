"""subscan.Camera and subscan.Settings: the same JSON as the CLI's camera.json and --settings."""
import copy
import json

import numpy as np
import pytest

import subscan


def test_orbit_is_the_cli_camera(cli, sphere, tmp_path):
    cli("render", "synthetic:sphere", "-o", tmp_path / "a.png", "--width", 64, "--height", 48,
        "--yaw", 75, "--pitch", -10, "--fovy", 50, "--export-buffers", tmp_path)
    camera = subscan.Camera.orbit(sphere, yaw=75, pitch=-10, fovy=50, width=64, height=48)
    assert camera == subscan.Camera.load(tmp_path / "camera.json")
    assert camera.to_json() == (tmp_path / "camera.json").read_text()


def test_sensor_is_the_cli_sensor_view(cli, data_dir, sphere, tmp_path):
    table = data_dir / "table_scene_mug_stereo_textured.pcd"
    cli("render", table, "-o", tmp_path / "a.png", "--view", "sensor", "--export-buffers",
        tmp_path)
    with pytest.warns(UserWarning):  # the stereo camera's NaN pixels are dropped
        cloud = subscan.load(table)
    camera = subscan.Camera.sensor(cloud)
    assert camera == subscan.Camera.load(tmp_path / "camera.json")
    assert (camera.width, camera.height) == (640, 480)
    # A given position wins over the file's; a cloud from arrays records none.
    at = subscan.Camera.sensor(sphere, sensor=(0.5, 0.2, 3.0), width=64, height=48)
    assert np.allclose(at.eye, (0.5, 0.2, 3.0), atol=1e-12)
    with pytest.raises(ValueError, match="records no sensor position"):
        subscan.Camera.sensor(subscan.Cloud(np.eye(3)))
    with pytest.raises(ValueError, match="more than 20 times"):
        subscan.Camera.sensor(sphere, sensor=(1e9, 0, 0))


def test_json_round_trip_and_attributes():
    camera = subscan.Camera.look_at(eye=(0, 1, 5), target=(0, 0, 0), width=320, height=200,
                                    fovy=30, near=0.5, far=20)
    assert (camera.width, camera.height, camera.fovy, camera.near, camera.far) == \
        (320, 200, 30, 0.5, 20)
    np.testing.assert_allclose(camera.eye, [0, 1, 5], atol=1e-12)  # inverting the view matrix
    text = camera.to_json()
    assert subscan.Camera.from_json(text) == camera
    assert subscan.Camera.from_json(json.loads(text)) == camera
    view = camera.view
    # The view maps the eye to the origin and the target to -Z.
    np.testing.assert_allclose(view @ [0, 1, 5, 1], [0, 0, 0, 1], atol=1e-12)
    target = view @ [0, 0, 0, 1]
    assert target[2] < 0 and abs(target[0]) < 1e-12 and abs(target[1]) < 1e-12
    same = subscan.Camera(320, 200, fovy=30, near=0.5, far=20, view=view)
    assert same == camera
    np.testing.assert_array_equal(same.projection, camera.projection)
    camera.width = 100
    assert camera.width == 100 and camera != same


def test_look_at_fits_near_and_far_to_a_cloud(sphere):
    camera = subscan.Camera.look_at((0, 0, 4), (0, 0, 0), cloud=sphere)
    # Near and far hug the sphere around the bounds (as Camera.orbit's), with a margin of 2 %
    # of its radius; the bounds' middle is within 3e-3 of the origin, hence the tolerance.
    lo, hi = sphere.bounds
    radius = 0.5 * np.linalg.norm(hi - lo)
    assert camera.near == pytest.approx(4 - 1.02 * radius, abs=3e-3)
    assert camera.far == pytest.approx(4 + 1.02 * radius, abs=3e-3)
    assert 1.7 < radius < 1.75  # the box around a unit sphere: sqrt(3)


@pytest.mark.parametrize("make, message", [
    (lambda: subscan.Camera(width=0), "the camera size 0x720 is outside 1..65536"),
    (lambda: subscan.Camera(fovy=180), "the camera's fovy_deg 180 is outside (0, 180)"),
    (lambda: subscan.Camera(near=2, far=1), "the camera needs 0 < near < far (finite)"),
    (lambda: subscan.Camera(view=np.eye(3)), "the camera's 'view' needs 4 rows of 4 numbers"),
    (lambda: subscan.Camera(view=np.full((4, 4), np.nan)),
     "the camera's 'view' holds a non-finite number"),
    (lambda: subscan.Camera.from_json("{}"), "the camera has no 'width'"),
    (lambda: subscan.Camera.from_json("{"), "not valid JSON (byte 2)"),
    (lambda: subscan.Camera.look_at((0, 0, 1), (0, 0, 1), near=1, far=2),
     "eye and target are the same point"),
    (lambda: subscan.Camera.look_at((0, 0, 1), (0, 0, 0), up=(0, 0, 1), near=1, far=2),
     "up is parallel to the line of sight (or zero)"),
    (lambda: subscan.Camera.look_at((0, 0, 1), (0, 0, 0)),
     "look_at needs near and far, or a cloud to fit them to"),
    (lambda: subscan.Camera.look_at((0, 0), (0, 0, 0), near=1, far=2), "eye must be 3 numbers"),
])
def test_bad_cameras_raise_value_error(make, message):
    with pytest.raises(ValueError) as error:
        make()
    assert str(error.value) == message


@pytest.mark.parametrize("keywords, message", [
    ({"pitch": 91}, "pitch 91 is outside -90..90"),
    ({"fovy": 0.5}, "fovy 0.5 is outside 1..170"),
    ({"distance": -1}, "distance -1 must be positive"),
    ({"up": "x"}, "up 'x' is not auto, y, z or -y"),
    ({"width": 0}, "width 0 is outside 1..65536"),
])
def test_bad_orbits_raise_value_error(sphere, keywords, message):
    with pytest.raises(ValueError) as error:
        subscan.Camera.orbit(sphere, **keywords)
    assert str(error.value) == message


def test_camera_file_errors_name_the_file(cli, tmp_path):
    bad = tmp_path / "camera.json"
    bad.write_text('{"width": 10}')
    with pytest.raises(subscan.Error) as error:
        subscan.Camera.load(bad)
    assert str(error.value) == f"{bad}: the camera has no 'height'"


def test_default_settings_are_the_cli_defaults(cli, tmp_path):
    cli("render", "synthetic:sphere", "-o", tmp_path / "a.png", "--width", 8, "--height", 8,
        "--save-settings", tmp_path / "defaults.json")
    assert subscan.Settings().to_json() == (tmp_path / "defaults.json").read_text()
    assert subscan.Settings.load(tmp_path / "defaults.json") == subscan.Settings()


def test_attribute_access_reads_and_writes_keys():
    settings = subscan.Settings(raster={"mode": "sss"}, scattering={"material": "skin1"})
    assert settings.raster.mode == "sss" and settings.scattering.material == "skin1"
    settings.surface.visibility_threshold = 0.25
    settings.raster.background_srgb = np.array([0.0, 0.5, 1.0])
    settings.temporal.max_frames = np.int64(64)
    assert settings.to_dict()["surface"]["visibility_threshold"] == 0.25
    assert settings.raster.background_srgb == [0.0, 0.5, 1.0]
    assert settings.temporal.max_frames == 64
    assert "visibility_threshold" in dir(settings.surface)
    assert set(dir(settings)) >= {"raster", "surface", "shading", "scattering", "temporal"}
    other = copy.deepcopy(settings)
    other.raster.mode = "points"
    assert settings.raster.mode == "sss" and other != settings
    settings.update({"raster": {"mode": "points"}})
    assert other == settings
    assert subscan.Settings.from_json(settings.to_json()) == settings


def test_typos_and_bad_values_raise():
    settings = subscan.Settings()
    with pytest.raises(AttributeError, match=r"unknown setting 'mdoe' in 'raster' \(expected one of: mode, "):
        settings.raster.mdoe = "surface"
    with pytest.raises(AttributeError, match="unknown setting 'mdoe' in 'raster'"):
        settings.raster.mdoe
    with pytest.raises(AttributeError, match=r"unknown settings section 'rastr' \(expected raster, "):
        settings.rastr
    with pytest.raises(AttributeError, match="cannot replace 'raster'"):
        settings.raster = {}
    with pytest.raises(ValueError) as error:
        settings.shading.specular = 7
    assert str(error.value) == "the setting 'specular' = 7 is outside 0..1"
    with pytest.raises(ValueError) as error:
        settings.raster.mode = "voxels"
    assert str(error.value).startswith("'voxels' is not a render mode (expected one of: points,")
    with pytest.raises(ValueError) as error:
        settings.raster.point_size = "big"
    assert str(error.value) == "the setting 'point_size' has the wrong type"
    with pytest.raises(ValueError) as error:
        settings.raster.mode = {1, 2}
    assert str(error.value) == "mode: a set cannot be written as JSON"
    with pytest.raises(ValueError, match="unknown settings section 'raser'"):
        subscan.Settings(raser={})
    with pytest.raises(ValueError, match="not valid JSON"):
        subscan.Settings.from_json("{")
    assert settings == subscan.Settings()  # nothing above changed anything


def test_settings_file_errors_name_the_file(cli, tmp_path):
    bad = tmp_path / "settings.json"
    bad.write_text('{"raster": {"point_size": 100}}')
    with pytest.raises(subscan.Error) as error:
        subscan.Settings.load(bad)
    assert str(error.value) == cli.error("render", "synthetic:sphere", "-o", tmp_path / "x.png",
                                         "--settings", bad)
