"""subscan.Cloud and subscan.load: numpy arrays in and out, and every bad array refused."""
import sys
import types
import warnings

import numpy as np
import pytest

import subscan


def random_points(count=1000, seed=0, offset=0.0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.0, 1.0, size=(count, 3)) + offset


def float32_tolerance(points):
    """Positions are float32 relative to a float64 origin inside the bounds, so no position is
    further from it than the extent, and rounding to float32 moves it by at most half a step
    there (2^-24 of the extent); the float64 sums add nothing measurable."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    return np.abs(hi - lo).max() * 2.0 ** -24


def test_points_colors_intensity_normals_round_trip():
    points = random_points()
    rng = np.random.default_rng(1)
    colors = rng.integers(0, 256, size=(1000, 3), dtype=np.uint8)
    intensity = rng.uniform(0, 1000, size=1000).astype(np.float32)
    normals = rng.normal(size=(1000, 3)).astype(np.float32)
    cloud = subscan.Cloud(points, colors=colors, intensity=intensity, normals=normals)
    assert len(cloud) == 1000
    assert cloud.format == "numpy"
    assert cloud.points.dtype == np.float64 and cloud.points.shape == (1000, 3)
    np.testing.assert_allclose(cloud.points, points, rtol=0, atol=float32_tolerance(points))
    np.testing.assert_array_equal(cloud.colors, colors)
    np.testing.assert_array_equal(cloud.intensity, intensity)
    np.testing.assert_array_equal(cloud.normals, normals)
    np.testing.assert_array_equal(cloud.bounds, [points.min(axis=0), points.max(axis=0)])
    assert cloud.triangles is None


def test_far_from_the_origin_keeps_precision():
    """UTM-sized coordinates: the float64 offset keeps millimetres (float32 alone would keep
    only 0.5 m at 5e6)."""
    points = random_points(offset=np.array([5.0e5, 5.0e6, 100.0]))
    cloud = subscan.Cloud(points)
    np.testing.assert_allclose(cloud.points, points, rtol=0, atol=float32_tolerance(points))
    assert np.abs(cloud.points - points).max() < 1e-6


def test_float32_and_float64_and_integers_give_the_same_cloud():
    # Whole numbers 0..200: exact in every one of these types, and in float32 positions.
    points = np.round((random_points() + 1.0) * 100.0)
    expected = subscan.Cloud(points).points
    np.testing.assert_array_equal(expected, points)
    for dtype in (np.float32, np.int32, np.int64, np.uint16, np.uint8, np.float16):
        cloud = subscan.Cloud(points.astype(dtype))
        np.testing.assert_array_equal(cloud.points, expected, err_msg=str(dtype))
    np.testing.assert_array_equal(subscan.Cloud(points.tolist()).points, expected)
    np.testing.assert_array_equal(subscan.Cloud(points.astype(">f8")).points, expected)
    np.testing.assert_array_equal(subscan.Cloud(points, colors=np.full((1000, 3), 7, ">u2")).colors,
                                  np.full((1000, 3), 7, np.uint8))


def test_non_contiguous_arrays_are_read_where_they_lie():
    table = random_points(2000).reshape(1000, 6)  # x y z nx ny nz interleaved
    contiguous = subscan.Cloud(np.ascontiguousarray(table[:, :3]),
                               normals=np.ascontiguousarray(table[:, 3:]))
    strided = subscan.Cloud(table[:, :3], normals=table[:, 3:])
    np.testing.assert_array_equal(strided.points, contiguous.points)
    np.testing.assert_array_equal(strided.normals, contiguous.normals)
    fortran = subscan.Cloud(np.asfortranarray(table[:, :3]))
    np.testing.assert_array_equal(fortran.points, contiguous.points)
    reversed_rows = subscan.Cloud(table[::-1, :3])
    np.testing.assert_array_equal(reversed_rows.points, contiguous.points[::-1])


def test_colors_as_floats_integers_and_with_alpha():
    points = random_points(4)
    expected = np.array([[0, 0, 0], [255, 255, 255], [128, 64, 32], [1, 2, 3]], dtype=np.uint8)
    np.testing.assert_array_equal(subscan.Cloud(points, colors=expected / 255.0).colors, expected)
    np.testing.assert_array_equal(subscan.Cloud(points, colors=expected.astype(np.int64)).colors,
                                  expected)
    rgba = np.concatenate([expected, np.full((4, 1), 7, np.uint8)], axis=1)
    np.testing.assert_array_equal(subscan.Cloud(points, colors=rgba).colors, expected)


def test_views_are_read_only_and_keep_the_cloud_alive():
    colors = np.full((10, 3), 9, np.uint8)
    cloud = subscan.Cloud(random_points(10), colors=colors, intensity=np.arange(10.0))
    view, intensity = cloud.colors, cloud.intensity
    assert not view.flags.writeable and not intensity.flags.writeable
    with pytest.raises(ValueError):
        view[0, 0] = 1
    del cloud  # the views hold it
    np.testing.assert_array_equal(view, colors)
    np.testing.assert_array_equal(intensity, np.arange(10.0))
    # points is a new array of the caller's own.
    cloud = subscan.Cloud(random_points(10))
    points = cloud.points
    points[:] = 0
    assert np.abs(cloud.points).max() > 0


def test_the_caller_may_change_its_arrays_afterwards():
    points = random_points(10)
    cloud = subscan.Cloud(points)
    before = cloud.points.copy()
    points[:] = 5
    np.testing.assert_array_equal(cloud.points, before)


@pytest.mark.parametrize("points, message", [
    (np.zeros((10, 2)), "points must be an array of shape N×3, not 10×2"),
    (np.zeros(30), "points must be an array of shape N×3, not 30"),
    (np.zeros((2, 3, 3)), "points must be an array of shape N×3, not 2×3×3"),
    (np.float64(1.0), "points must be an array, not a scalar"),
    (np.zeros((0, 3)), "points is empty: a cloud needs at least one point"),
    (np.zeros((3, 3), dtype=complex), "points must hold real numbers, not complex128"),
    (np.array([["a", "b", "c"]]), "points must hold real numbers, not <U1"),
    (np.zeros((3, 3), dtype=bool), "points must hold real numbers, not bool"),
    (np.array([[0, 0, 0], [1, np.nan, 2]]),
     "points row 1 is (1, nan, 2): coordinates must be finite and within ±1e15"),
    (np.array([[np.inf, 0, 0]], dtype=np.float32),
     "points row 0 is (inf, 0, 0): coordinates must be finite and within ±1e15"),
    (np.array([[0, 0, 1e16]]),
     "points row 0 is (0, 0, 1e+16): coordinates must be finite and within ±1e15"),
    ("not an array", "points must be an array, not str"),
    (None, "points must be an array, not NoneType"),
    ([[0, 0, 0], [1, 2]], "points is not an array (got list)"),
])
def test_bad_points_raise_value_error(points, message):
    with pytest.raises(ValueError) as error:
        subscan.Cloud(points)
    assert str(error.value) == message


@pytest.mark.parametrize("keyword, value, message", [
    ("colors", np.zeros((4, 3), np.uint8), "colors has 4 rows but points has 5"),
    ("colors", np.zeros((5, 2), np.uint8), "colors must be an array of shape N×3 or N×4, not 5×2"),
    ("colors", np.full((5, 3), 1.5), "colors row 0 has 1.5: float colours must lie in 0..1"),
    ("colors", np.full((5, 3), np.nan), "colors row 0 has nan: float colours must lie in 0..1"),
    ("colors", np.full((5, 3), 300), "colors row 0 has 300: integer colours must lie in 0..255"),
    ("colors", np.full((5, 3), -1), "colors row 0 has -1: integer colours must lie in 0..255"),
    ("normals", np.zeros((5, 4)), "normals must be an array of shape N×3, not 5×4"),
    ("normals", np.array([[0, 0, 1]] * 4 + [[np.nan, 0, 1]]),
     "normals row 4 is not finite (NaN or infinite)"),
    ("intensity", np.zeros(6), "intensity has 6 rows but points has 5"),
    ("intensity", np.zeros((5, 2)), "intensity must be an array of shape N×1 (or N), not 5×2"),
    ("intensity", np.array([0, 1, np.inf, 3, 4]), "intensity row 2 is not finite (NaN or infinite)"),
    ("triangles", np.array([[0, 1, 5]]), "triangles row 0 uses vertex 5, outside 0..4"),
    ("triangles", np.array([[0, -1, 2]]), "triangles row 0 uses vertex -1, outside 0..4"),
    ("triangles", np.array([[0.0, 1.0, 2.0]]), "triangles must hold integer vertex indices, not float64"),
])
def test_bad_attributes_raise_value_error(keyword, value, message):
    with pytest.raises(ValueError) as error:
        subscan.Cloud(random_points(5), **{keyword: value})
    assert str(error.value) == message


def test_triangles_make_a_mesh():
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    faces = np.array([[0, 1, 2], [0, 1, 3]])
    cloud = subscan.Cloud(points, triangles=faces)
    assert cloud.triangles.dtype == np.uint32
    np.testing.assert_array_equal(cloud.triangles, faces)


def test_spacing_is_the_estimate_subscan_info_reports(cli, tmp_path):
    grid = np.stack(np.meshgrid(np.arange(30), np.arange(30), [0.0]), axis=-1).reshape(-1, 3)
    assert subscan.Cloud(grid * 0.5).spacing == pytest.approx(0.5)  # exactly, up to float32
    cloud = subscan.load("synthetic:torus?points=3000")
    info = cli.json("info", "synthetic:torus?points=3000", "--json")
    assert cloud.spacing == info["spacing"]
    assert len(cloud) == info["points"] == 3000
    np.testing.assert_array_equal(cloud.bounds, [info["bounds_min"], info["bounds_max"]])
    assert subscan.Cloud(np.zeros((3, 3))).spacing == 0.0  # no two distinct points


def test_load_reads_files_like_the_cli(cli, data_dir):
    path = data_dir / "bun_zipper_res4.ply"
    cloud = subscan.load(path)  # a pathlib.Path; str works too
    info = cli.json("info", path, "--json")
    assert cloud.format == info["format"] == "ply"
    assert len(cloud) == info["points"]
    assert len(cloud.triangles) == info["faces"]
    np.testing.assert_array_equal(cloud.bounds, [info["bounds_min"], info["bounds_max"]])
    las = subscan.load(str(data_dir / "simple.las"))
    assert las.format == "las" and las.intensity is not None and las.colors is not None


def test_classification_is_the_las_class_codes(data_dir):
    # simple.las: 789 unclassified (1) and 276 ground (2) points, counted from its bytes by a
    # separate script; .las and .laz of Autzen give the same codes in the same order.
    las = subscan.load(data_dir / "simple.las")
    codes = las.classification
    assert codes.dtype == np.uint8 and codes.shape == (len(las),)
    assert not codes.flags.writeable
    assert np.count_nonzero(codes == 2) == 276 and np.count_nonzero(codes == 1) == 789
    autzen_las = subscan.load(data_dir / "autzen_trim.las").classification
    np.testing.assert_array_equal(autzen_las, subscan.load(data_dir / "autzen_trim.laz").classification)
    assert "classification" in repr(las)
    # Only LAS files carry one.
    assert subscan.load("synthetic:sphere?points=100").classification is None


def test_load_errors_carry_the_cli_sentence(cli, tmp_path):
    for source in (tmp_path / "missing.ply", "synthetic:teapot"):
        with pytest.raises(subscan.Error) as error:
            subscan.load(source)
        assert str(error.value) == cli.error("info", source)
    broken = tmp_path / "broken.ply"
    broken.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 10\nend_header\n")
    with pytest.raises(subscan.Error) as error:
        subscan.load(broken)
    assert str(error.value) == cli.error("info", broken)
    with pytest.raises(TypeError):
        subscan.load(42)


def test_reader_warnings_become_python_warnings(tmp_path):
    xyz = tmp_path / "nan.xyz"
    xyz.write_text("0 0 0\n1 0 0\nnan 0 0\n0 1 0\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cloud = subscan.load(xyz)
    assert len(cloud) == 3
    assert any("dropped 1 of 4 points" in str(w.message) and str(xyz) in str(w.message)
               for w in caught), [str(w.message) for w in caught]


class FakeOpen3d:
    """Just enough of Open3D's PointCloud API (points, colors and normals as Vector3dVector,
    has_colors/has_normals) to exercise the conversions where Open3D is not installed."""

    def __init__(self):
        module = types.ModuleType("open3d")

        class Vector3dVector(list):
            def __init__(self, array):
                super().__init__(np.asarray(array, dtype=np.float64).tolist())

        class PointCloud:
            def __init__(self):
                self.points, self.colors, self.normals = Vector3dVector(np.zeros((0, 3))), \
                    Vector3dVector(np.zeros((0, 3))), Vector3dVector(np.zeros((0, 3)))

            def has_colors(self):
                return len(self.colors) > 0

            def has_normals(self):
                return len(self.normals) > 0

        module.geometry = types.SimpleNamespace(PointCloud=PointCloud)
        module.utility = types.SimpleNamespace(Vector3dVector=Vector3dVector)
        self.module = module


def open3d_modules():
    modules = [pytest.param("fake", id="fake-open3d")]
    try:
        import open3d  # noqa: F401
        modules.append(pytest.param("real", id="open3d"))
    except ImportError:
        modules.append(pytest.param("real", id="open3d",
                                    marks=pytest.mark.skip(reason="Open3D is not installed")))
    return modules


@pytest.mark.parametrize("which", open3d_modules())
def test_open3d_round_trip(which, monkeypatch):
    if which == "fake":
        monkeypatch.setitem(sys.modules, "open3d", FakeOpen3d().module)
    points = random_points(50)
    colors = np.random.default_rng(2).integers(0, 256, (50, 3), dtype=np.uint8)
    normals = np.tile([0.0, 0.0, 1.0], (50, 1))
    cloud = subscan.Cloud(points, colors=colors, normals=normals)
    pcd = cloud.to_open3d()
    np.testing.assert_allclose(np.asarray(pcd.points), cloud.points, rtol=0, atol=0)
    np.testing.assert_allclose(np.asarray(pcd.colors), colors / 255.0, rtol=0, atol=1e-15)
    back = subscan.Cloud.from_open3d(pcd)
    assert back.format == "open3d"
    np.testing.assert_array_equal(back.colors, colors)
    np.testing.assert_array_equal(back.normals, normals)
    np.testing.assert_allclose(back.points, points, rtol=0, atol=float32_tolerance(points))


def test_to_open3d_without_open3d_is_an_import_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "open3d", None)  # import open3d now raises ImportError
    with pytest.raises(ImportError, match="Cloud.to_open3d needs Open3D"):
        subscan.Cloud(random_points(3)).to_open3d()


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("count", [1, 2, 3, 5, 100_003])
def test_large_and_odd_sized_arrays_keep_exact_bounds(dtype, count):
    """Contiguous arrays go through one vectorised pass in blocks of 4 points; the last 0-3
    points take another path, so the extremes are put there and in the middle."""
    points = random_points(count, seed=count).astype(dtype)
    points[count // 2] = [-7, 8, -9]
    points[-1] = [7, -8, 9] if count > 1 else points[-1]
    cloud = subscan.Cloud(points)
    np.testing.assert_array_equal(cloud.bounds, [points.min(axis=0), points.max(axis=0)])
    np.testing.assert_allclose(cloud.points, points, rtol=0, atol=float32_tolerance(points))
    strided = subscan.Cloud(np.repeat(points, 2, axis=1)[:, ::2])  # the same values, strided
    np.testing.assert_array_equal(strided.bounds, cloud.bounds)
    np.testing.assert_allclose(strided.points, cloud.points, rtol=0,
                               atol=2 * float32_tolerance(points))  # two roundings


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("row", [0, 50_001, 100_002])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf, 2e15])
def test_bad_values_anywhere_in_large_arrays_are_found(dtype, row, bad):
    points = random_points(100_003).astype(dtype)
    points[row, 1] = bad
    with pytest.raises(ValueError, match=rf"^points row {row} is \("):
        subscan.Cloud(points)


def test_estimate_normals_returns_a_cloud_whose_normals_follow_the_surface():
    # A noiseless sphere of radius 2 seen from its centre: every normal is radial and, oriented
    # to the sensor there, points inwards; the neighbourhoods' asymmetry tilts them a little.
    rng = np.random.default_rng(3)
    directions = rng.normal(size=(20000, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    centre = np.array([5.0, -1.0, 2.0])
    cloud = subscan.Cloud(centre + 2.0 * directions)
    assert cloud.normals is None
    estimated = cloud.estimate_normals(sensor=centre)
    assert cloud.normals is None  # the original is immutable
    assert len(estimated) == len(cloud)
    normals = estimated.normals.astype(np.float64)
    cosines = np.einsum("ij,ij->i", normals, -directions)
    assert cosines.min() > 0.0  # every one faces the sensor
    # Random points are less even than a grid: measured 0.44 degrees mean (2.1 at most); 1
    # degree leaves room for another platform's rounding, unrelated normals give 57.
    assert np.degrees(np.arccos(np.clip(cosines, -1.0, 1.0))).mean() < 1.0
    with pytest.raises(ValueError, match="sensor"):
        cloud.estimate_normals(sensor=(1.0, 2.0))
