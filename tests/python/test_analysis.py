"""subscan.materials, fit_profile, scan and evaluate: what the CLI's --json prints."""
import numpy as np
import pytest

import subscan


def test_materials_are_the_cli_list(cli):
    assert subscan.materials() == cli.json("materials", "--json")


@pytest.mark.parametrize("material, gaussians, profile", [("marble", 3, "dipole"),
                                                          ("skin1", 2, "burley")])
def test_fit_profile_is_the_cli_fit(cli, material, gaussians, profile):
    expected = cli.json("fit-profile", "--material", material, "--gaussians", gaussians,
                        "--profile", profile, "--json")
    assert subscan.fit_profile(material, gaussians, profile=profile) == expected


def test_bad_fits_raise_value_error(cli):
    with pytest.raises(ValueError) as error:
        subscan.fit_profile("unobtainium", 2)
    assert str(error.value) == cli.error("fit-profile", "--material", "unobtainium",
                                         "--gaussians", 2)
    with pytest.raises(ValueError, match="gaussians 0 is outside 1..12"):
        subscan.fit_profile("marble", 0)
    with pytest.raises(ValueError, match="profile 'gauss' is not dipole or burley"):
        subscan.fit_profile("marble", 2, profile="gauss")


def test_scan_is_the_cli_scan(cli, tmp_path):
    cli("scan", "synthetic:box-with-hole", "-o", tmp_path / "scan.ply", "--views", 3,
        "--resolution", 40, "--noise", "0.1h", "--normals", "--seed", 7)
    expected = subscan.load(tmp_path / "scan.ply")
    cloud = subscan.scan("synthetic:box-with-hole", views=3, resolution=40, noise="0.1h",
                         normals=True, seed=7)
    assert cloud.format == "scan" and len(cloud) == len(expected) > 1000
    # The PLY holds float32 file coordinates, re-centred on loading: each side is within a
    # float32 step (2^-23 relative) of the largest coordinate of the scan itself.
    tolerance = np.abs(expected.points).max() * 2.0 ** -23
    np.testing.assert_allclose(cloud.points, expected.points, rtol=0, atol=tolerance)
    np.testing.assert_array_equal(cloud.colors, expected.colors)
    np.testing.assert_array_equal(cloud.normals, expected.normals)


@pytest.mark.parametrize("mode, cli_options, settings", [
    ("station", ["--station", 5, 1.5, 3, "--azimuth-steps", 360, "--elevation-steps", 60],
     {"position": [5, 1.5, 3], "azimuth_steps": 360, "elevation_steps": 60}),
    ("airborne", ["--line-spacing", 4, "--points-per-line", 120],
     {"line_spacing": 4, "points_per_line": 120}),
])
def test_lidar_scans_are_the_cli_scans(cli, tmp_path, mode, cli_options, settings):
    cli("scan", "synthetic:outdoor", "-o", tmp_path / "scan.ply", "--mode", mode, *cli_options)
    expected = subscan.load(tmp_path / "scan.ply")
    cloud = subscan.scan("synthetic:outdoor", mode=mode, **{mode: settings})
    assert len(cloud) == len(expected) > 1000
    # float32 file coordinates in the PLY, as above.
    tolerance = np.abs(expected.points).max() * 2.0 ** -23
    np.testing.assert_allclose(cloud.points, expected.points, rtol=0, atol=tolerance)


def test_bad_lidar_scans_raise_value_error():
    with pytest.raises(ValueError, match="mode 'lidar' is not object, station or airborne"):
        subscan.scan("synthetic:outdoor", mode="lidar")
    with pytest.raises(ValueError, match="'station.azimuth' is not a scanner setting"):
        subscan.scan("synthetic:outdoor", mode="station", station={"azimuth": 3})


def test_scan_of_a_cloud_with_triangles_and_bad_scans(cli, tmp_path):
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float)
    mesh = subscan.Cloud(points, triangles=[[0, 1, 2], [1, 3, 2]])
    cloud = subscan.scan(mesh, views=1, resolution=16)
    assert len(cloud) > 50 and np.abs(cloud.points[:, 2]).max() < 1e-6  # on the square
    assert cloud.colors is None  # a mesh without colours gives none (color='auto')
    with pytest.raises(ValueError) as error:
        subscan.scan("synthetic:teapot")
    assert str(error.value) == cli.error("scan", "synthetic:teapot", "-o", tmp_path / "x.ply")
    with pytest.raises(ValueError, match="noise '-1' must be a distance >= 0"):
        subscan.scan("synthetic:sphere", noise=-1)
    with pytest.raises(ValueError, match="color 'red' is not auto, none, scene or marble"):
        subscan.scan("synthetic:sphere", color="red")
    with pytest.raises(subscan.Error, match="has no faces; scan needs a triangle mesh"):
        subscan.scan(subscan.Cloud(points))


def test_evaluate_is_the_cli_eval(cli):
    expected = cli.json("eval", "synthetic:sphere", "--views", 2, "--width", 48, "--height",
                        48, "--json")
    report = subscan.evaluate("synthetic:sphere", views=2, width=48, height=48)
    assert report == expected
    assert report["methods"]["surface"]["coverage"] > 0.9  # a real measurement, not zeros


def test_evaluate_a_mesh_file_or_cloud(cli, data_dir):
    mesh = data_dir / "bun_zipper_res4.ply"
    expected = cli.json("eval", mesh, "--views", 1, "--width", 48, "--height", 48, "--json")
    assert subscan.evaluate(mesh, views=1, width=48, height=48) == expected
    assert subscan.evaluate(subscan.load(mesh), views=1, width=48, height=48) == expected


def test_bad_evaluations_raise(sphere):
    with pytest.raises(subscan.Error, match="has no faces; evaluate needs a triangle mesh"):
        subscan.evaluate(sphere)
    with pytest.raises(ValueError, match="views 0 is outside 1..360"):
        subscan.evaluate("synthetic:sphere", views=0)
    with pytest.raises(ValueError, match="width 8 is outside 16..8192"):
        subscan.evaluate("synthetic:sphere", width=8)
