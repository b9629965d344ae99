"""subscan.Renderer against `subscan render`: the same pictures byte for byte, the same buffers
as --export-buffers, several renderers and threads, the GIL released, every bad call refused."""
import gc
import threading
import time

import numpy as np
import pytest

import subscan

from conftest import read_pfm, read_png

SCAN = "synthetic:torus?points=20000"
WIDTH, HEIGHT = 96, 72


@pytest.fixture(scope="module")
def torus():
    return subscan.load(SCAN)


@pytest.fixture(scope="module")
def renderer(torus):
    with subscan.Renderer(torus) as renderer:
        yield renderer


@pytest.fixture(scope="module")
def camera(torus):
    """Off the default orbit, so that the CLI reads it from --camera."""
    return subscan.Camera.look_at((0.15, 0.2, 0.25), (0.02, 0.0, 0.0), width=WIDTH, height=HEIGHT,
                                  fovy=40, cloud=torus)


@pytest.fixture(scope="module")
def settings():
    """Not the defaults: the CLI must read them from --settings to match."""
    settings = subscan.Settings()
    settings.raster.background_srgb = [0.1, 0.2, 0.3]
    settings.raster.point_size = 3
    settings.surface.visibility_threshold = 0.12
    settings.shading.specular = 0.3
    settings.scattering.method = "both"
    settings.scattering.material = "marble-jimenez"
    return settings


def cli_render(cli, tmp_path, camera, settings, mode, *extra):
    camera.save(tmp_path / "camera.json")
    settings.save(tmp_path / "settings.json")
    cli("render", SCAN, "-o", tmp_path / "cli.png", "--camera", tmp_path / "camera.json",
        "--settings", tmp_path / "settings.json", "--mode", mode, *extra)
    return read_png(tmp_path / "cli.png")


@pytest.mark.parametrize("mode", ["points", "points-gl", "splats", "surface", "sss"])
def test_render_equals_the_cli_png(cli, tmp_path, renderer, camera, settings, mode):
    expected = cli_render(cli, tmp_path, camera, settings, mode)
    image = renderer.render(camera, mode=mode, settings=settings)
    assert image.dtype == np.uint8 and image.shape == (HEIGHT, WIDTH, 3)
    assert (expected[:, :, 3] == 255).all()  # the CLI's PNG is opaque: RGB is all it holds
    np.testing.assert_array_equal(image, expected[:, :, :3])
    # A picture, not a blank: the torus covers a good part of it, shaded where lit.
    assert (image != image[0, 0]).any(axis=2).mean() > 0.1
    if mode in ("surface", "sss"):
        assert len(np.unique(image.reshape(-1, 3), axis=0)) > 50


def test_samples_equal_the_cli_samples(cli, tmp_path, renderer, camera, settings):
    expected = cli_render(cli, tmp_path, camera, settings, "surface", "--samples", 4)
    image = renderer.render(camera, mode="surface", settings=settings, samples=4)
    np.testing.assert_array_equal(image, expected[:, :, :3])
    # Each call starts afresh, as each command does: the same call gives the same picture.
    np.testing.assert_array_equal(renderer.render(camera, "surface", settings, samples=4), image)


def srgb8(linear):
    """The sRGB encoding of core/Srgb.h in float64; the C++ one is float32, so a value on a
    rounding boundary may land one step away (checked below to be rare)."""
    linear = np.clip(linear.astype(np.float64), 0.0, 1.0)
    encoded = np.where(linear <= 0.0031308, linear * 12.92,
                       1.055 * np.power(linear, 1.0 / 2.4) - 0.055)
    return np.round(encoded * 255.0).astype(np.int64)


@pytest.mark.parametrize("mode, files", [
    ("points", ["depth"]),
    ("surface", ["depth", "normals", "radiance"]),
    ("sss", ["depth", "normals", "radiance", "single", "sigma_s", "sigma_a"]),
])
def test_buffers_equal_the_cli_export(cli, tmp_path, renderer, camera, settings, mode, files):
    expected_png = cli_render(cli, tmp_path, camera, settings, mode, "--export-buffers",
                              tmp_path / "buffers")
    image = renderer.render(camera, mode=mode, settings=settings, buffers=True)
    np.testing.assert_array_equal(image, expected_png[:, :, :3])
    buffers = renderer.buffers()
    assert renderer.buffer_camera == subscan.Camera.load(tmp_path / "buffers" / "camera.json")
    expected_keys = {"depth", "color"} | ({"normals", "radiance", "mask"} if mode != "points" else set())
    assert set(buffers) == expected_keys | set(files)
    for name in files:
        expected = read_pfm(tmp_path / "buffers" / f"{name}.pfm")
        assert buffers[name].dtype == np.float32
        np.testing.assert_array_equal(buffers[name], expected, err_msg=name)
    depth = buffers["depth"]
    assert depth.shape == (HEIGHT, WIDTH)
    covered = np.isfinite(depth)
    assert 0.05 < covered.mean() < 0.95  # the torus is in the picture, not all of it
    color_png = read_png(tmp_path / "buffers" / "color.png")
    np.testing.assert_array_equal(color_png[:, :, 3], np.where(covered, 255, 0))
    difference = np.abs(srgb8(buffers["color"]) - color_png[:, :, :3])
    assert difference.max() <= 1 and (difference > 0).mean() < 0.01
    if mode != "points":
        mask_png = read_png(tmp_path / "buffers" / "mask.png")
        np.testing.assert_array_equal(buffers["mask"] * 255, mask_png)
        np.testing.assert_array_equal(buffers["mask"], covered.astype(np.float32))


def test_default_camera_and_mode_are_the_cli_orbit_and_surface(cli, tmp_path, torus, renderer):
    cli("render", SCAN, "-o", tmp_path / "cli.png", "--mode", "surface")
    np.testing.assert_array_equal(renderer.render(), read_png(tmp_path / "cli.png")[:, :, :3])


def test_default_camera_takes_the_renderers_up_axis(cli, tmp_path, torus):
    cli("render", SCAN, "-o", tmp_path / "cli.png", "--mode", "surface", "--up", "z")
    with subscan.Renderer(torus, up="z") as renderer:
        np.testing.assert_array_equal(renderer.render(), read_png(tmp_path / "cli.png")[:, :, :3])


def test_timings_name_the_passes(renderer, camera):
    renderer.render(camera, mode="surface")
    timings = renderer.timings()
    assert "rasterize" in " ".join(timings) or len(timings) >= 3, timings
    assert all(ms >= 0.0 for ms in timings.values())
    renderer.render(camera, mode="points-gl")
    assert set(renderer.timings()) != set(timings)


def test_several_renderers_in_one_process(torus, camera, renderer):
    expected = renderer.render(camera, mode="surface")
    first, second = subscan.Renderer(torus), subscan.Renderer(torus)
    np.testing.assert_array_equal(first.render(camera, mode="surface"), expected)
    del first  # dropping one renderer's context leaves the others working
    np.testing.assert_array_equal(second.render(camera, mode="surface"), expected)
    np.testing.assert_array_equal(renderer.render(camera, mode="surface"), expected)
    second.close()
    with pytest.raises(subscan.Error, match="the renderer is closed"):
        second.render(camera)


def test_a_renderer_keeps_its_cloud(camera):
    # The renderer may read the cloud's points in place (no copy on Mesa): dropping the last
    # Python reference to the cloud must not free them under it. 3.2 M float32 positions are
    # 38 MB, above glibc's largest mmap threshold (32 MiB): freed, they would be unmapped and the
    # next render would crash; kept, the picture stays the same.
    torus = subscan.load(SCAN).points
    offsets = np.random.default_rng(2).normal(0.0, 1e-4, size=(160, 1, 3))
    cloud = subscan.Cloud((torus[np.newaxis] + offsets).reshape(-1, 3))
    with subscan.Renderer(cloud) as kept:
        before = kept.render(camera, mode="points")
        del cloud
        gc.collect()
        garbage = [np.full((20000, 3), 1e3) for _ in range(8)]
        after = kept.render(camera, mode="points")
        del garbage
    assert (before != before[0, 0]).any(axis=2).sum() > 500  # the torus, not a blank picture
    np.testing.assert_array_equal(after, before)


def test_renderers_on_threads(torus, camera, renderer):
    expected = {mode: renderer.render(camera, mode=mode) for mode in ("points", "surface")}
    results, errors = {}, []
    others = {mode: subscan.Renderer(torus) for mode in expected}

    def work(mode):
        try:
            for _ in range(3):
                results[mode] = others[mode].render(camera, mode=mode)
        except Exception as error:  # reported below: an exception in a thread is otherwise lost
            errors.append(error)

    threads = [threading.Thread(target=work, args=(mode,)) for mode in expected]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not errors, errors
    for mode in expected:
        np.testing.assert_array_equal(results[mode], expected[mode])
    # A renderer made on this thread renders on another one.
    thread = threading.Thread(target=work, args=("points",))
    thread.start()
    thread.join()
    assert not errors, errors


def longest_pause_during(call):
    """Runs `call` on another thread while this one keeps reading the clock, and returns the
    longest time this thread could not run while the call ran, and the call's duration. A call
    holding the GIL stops this thread for all of its time in C++; Python's switch interval
    (5 ms) alone would let it run often in between."""
    window = {}

    def timed():
        window["start"] = time.perf_counter()
        call()
        window["end"] = time.perf_counter()

    thread = threading.Thread(target=timed)
    ticks = []
    thread.start()
    while thread.is_alive():
        ticks.append(time.perf_counter())
    thread.join()
    inside = [window["start"]] + [t for t in ticks if window["start"] < t < window["end"]] + \
        [window["end"]]
    return max(np.diff(inside)), window["end"] - window["start"]


def test_the_gil_is_released_while_rendering_and_loading(torus):
    renderer = subscan.Renderer(torus)
    big = subscan.Camera.orbit(torus, width=1280, height=720)
    renderer.render(big, mode="sss")  # compiles the shaders: the timed call only renders
    for call in (lambda: renderer.render(big, mode="sss"),
                 lambda: subscan.load("synthetic:sculpture?points=100000")):
        pause, duration = longest_pause_during(call)
        assert duration > 0.1, "too short to tell"
        # Held, the GIL would stop this thread for nearly the whole call; released, only the
        # scheduler pauses it (a few ms, or tens on a busy machine with llvmpipe's threads).
        assert pause < 0.5 * duration, (pause, duration)


@pytest.mark.parametrize("call, error, message", [
    (lambda r, c: r.render(c, mode="voxels"), ValueError,
     "'voxels' is not a render mode (expected one of: points, points-gl, splats, surface, sss)"),
    (lambda r, c: r.render(c, samples=0), ValueError, "samples 0 is outside 1..2048"),
    (lambda r, c: r.render(c, mode="points", samples=4), ValueError,
     "samples needs the final picture of the surface or sss mode (the temporal filter "
     "anti-aliases reconstructed surfaces)"),
    (lambda r, c: r.render(c, settings={"raster": {"mode": "nope"}}), ValueError,
     "'nope' is not a render mode (expected one of: points, points-gl, splats, surface, sss)"),
    (lambda r, c: r.render(c, settings=42), TypeError,
     "settings must be a subscan.Settings, a dict or None, not int"),
    (lambda r, c: r.render(subscan.Camera(width=65536, height=65536, near=1, far=2)),
     subscan.Error, None),
])
def test_bad_render_calls_raise(renderer, camera, call, error, message):
    with pytest.raises(error) as raised:
        call(renderer, camera)
    if message is not None:
        assert str(raised.value) == message
    else:
        assert "is outside what the GPU can render" in str(raised.value)
    renderer.render(camera, mode="points")  # and the renderer still works


def test_buffers_need_a_render_that_kept_them(torus, camera):
    renderer = subscan.Renderer(torus)
    with pytest.raises(subscan.Error, match=r"no buffers: the last render\(\) did not keep them"):
        renderer.buffers()
    renderer.render(camera, mode="surface")
    with pytest.raises(subscan.Error, match="no buffers"):
        renderer.buffers()
    renderer.render(camera, mode="surface", buffers=True)
    assert "depth" in renderer.buffers()
    with pytest.raises(TypeError):
        subscan.Renderer("not a cloud")


def write_ply(path, points, colors=None, intensity=None):
    """A binary PLY of `points` (N×3), with 8-bit `colors` (N×3) and float `intensity` (N)
    where given."""
    fields = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")]
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {len(points)}",
              "property float x", "property float y", "property float z"]
    if colors is not None:
        fields += [("red", "u1"), ("green", "u1"), ("blue", "u1")]
        header += ["property uchar red", "property uchar green", "property uchar blue"]
    if intensity is not None:
        fields += [("intensity", "<f4")]
        header += ["property float intensity"]
    records = np.zeros(len(points), dtype=fields)
    for axis, name in enumerate("xyz"):
        records[name] = points[:, axis]
    if colors is not None:
        for channel, name in enumerate(("red", "green", "blue")):
            records[name] = colors[:, channel]
    if intensity is not None:
        records["intensity"] = intensity
    with open(path, "wb") as file:
        file.write(("\n".join(header + ["end_header"]) + "\n").encode("ascii"))
        file.write(records.tobytes())


@pytest.fixture(scope="module")
def scans_of_each_kind(torus, tmp_path_factory):
    """The torus's points as a PLY without colour, one with colour and one with intensity only
    (a speckle of it, as a scanner's confidence is: drawn as grey, it would show)."""
    directory = tmp_path_factory.mktemp("kinds")
    points = np.asarray(torus.points, dtype=np.float32)
    random = np.random.default_rng(7)
    colors = random.integers(0, 256, size=(len(points), 3), dtype=np.uint8)
    intensity = random.uniform(0.0, 1.0, size=len(points)).astype(np.float32)
    files = {"plain": directory / "plain.ply", "colour": directory / "colour.ply",
             "intensity": directory / "intensity.ply"}
    write_ply(files["plain"], points)
    write_ply(files["colour"], points, colors=colors)
    write_ply(files["intensity"], points, intensity=intensity)
    return files


def default_pictures_agree(cli, tmp_path, path, camera, *color):
    """`subscan render PATH` and subscan.Renderer(subscan.load(PATH)) with nothing but the
    camera and mode given (and the colouring, where `color` holds one): byte for byte."""
    camera.save(tmp_path / "camera.json")
    cli("render", path, "-o", tmp_path / "cli.png", "--camera", tmp_path / "camera.json",
        "--mode", "surface", *(("--color", color[0]) if color else ()))
    expected = read_png(tmp_path / "cli.png")[:, :, :3]
    keywords = {"color": color[0]} if color else {}
    with subscan.Renderer(subscan.load(path), **keywords) as renderer:
        image = renderer.render(camera, mode="surface")
    np.testing.assert_array_equal(image, expected)
    return image


@pytest.mark.parametrize("kind", ["plain", "colour", "intensity"])
def test_default_colouring_is_the_cli_one(cli, tmp_path, camera, scans_of_each_kind, kind):
    image = default_pictures_agree(cli, tmp_path, scans_of_each_kind[kind], camera)
    # Not only equal: by default intensity is not drawn (the auto colouring shows the grey of a
    # scan without colour), so the plain and intensity-only scans give one picture.
    if kind == "intensity":
        plain = default_pictures_agree(cli, tmp_path, scans_of_each_kind["plain"], camera)
        np.testing.assert_array_equal(image, plain)


def test_an_asked_colouring_is_the_cli_one(cli, tmp_path, camera, scans_of_each_kind):
    speckled = default_pictures_agree(cli, tmp_path, scans_of_each_kind["intensity"], camera,
                                      "intensity")
    plain = default_pictures_agree(cli, tmp_path, scans_of_each_kind["plain"], camera)
    assert (speckled != plain).any(axis=2).mean() > 0.05  # the intensity shows where asked


def test_the_stanford_bunny_default_is_the_cli_one(cli, tmp_path, data_dir):
    # The scan whose confidence channel the PLY reader takes as intensity (issue 41).
    path = data_dir / "bun_zipper_res2.ply"
    camera = subscan.Camera.orbit(subscan.load(path), yaw=40, width=160, height=120)
    default_pictures_agree(cli, tmp_path, path, camera)


@pytest.mark.parametrize("keywords, message", [
    ({"color": "plaid"}, "there is no colouring 'plaid'"),
    ({"up": "x"}, "up 'x' is not auto, y, z or -y"),
])
def test_bad_colourings_raise(torus, keywords, message):
    with pytest.raises(ValueError, match=message):
        subscan.Renderer(torus, **keywords)


def test_a_colouring_the_cloud_cannot_give_raises(torus, scans_of_each_kind):
    with pytest.raises(subscan.Error, match="the scan has no intensities to show"):
        subscan.Renderer(subscan.load(scans_of_each_kind["plain"]), color="intensity")


def test_a_streamed_view_is_the_one_render_streams(cli, tmp_path, data_dir):
    """subscan.load(..., lod="auto", camera=...) loads the octree nodes `subscan render`
    streams for that view within the budget, with their levels' spacing: the same picture."""
    path = data_dir / "lone_star.copc.laz"
    whole = len(subscan.load(path))  # lod="off", the default: every point
    overview = subscan.load(path, lod="auto")
    assert 0 < len(overview) < whole
    camera = subscan.Camera.orbit(overview, yaw=30, pitch=35, width=160, height=120)
    view = subscan.load(path, lod="auto", camera=camera, point_budget=100_000)
    assert 10_000 < len(view) <= 100_000
    camera.save(tmp_path / "camera.json")
    cli("render", path, "-o", tmp_path / "cli.png", "--camera", tmp_path / "camera.json",
        "--mode", "surface", "--point-budget", 100_000)
    with subscan.Renderer(view) as renderer:
        image = renderer.render(camera, mode="surface")
    np.testing.assert_array_equal(image, read_png(tmp_path / "cli.png")[:, :, :3])
    assert (image != image[0, 0]).any(axis=2).mean() > 0.1  # a picture, not a blank
    # A larger budget loads more of the nodes the view shows (not all: at 160x120 the deepest
    # add no detail).
    assert len(view) < len(subscan.load(path, lod="on", camera=camera, point_budget=whole)) < whole
    # What cannot be streamed: "on" refuses it, "auto" loads it whole; a bad mode is refused.
    ply = data_dir / "bun_zipper_res4.ply"
    with pytest.raises(subscan.Error):
        subscan.load(ply, lod="on")
    assert len(subscan.load(ply, lod="auto")) == len(subscan.load(ply))
    with pytest.raises(ValueError):
        subscan.load(path, lod="sometimes")
