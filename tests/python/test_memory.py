"""No memory growth over 500 renders."""
import gc
import os

import subscan


def resident_bytes():
    with open("/proc/self/statm") as statm:
        return int(statm.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_no_memory_growth_over_500_renders(sphere):
    renderer = subscan.Renderer(sphere)
    camera = subscan.Camera.orbit(sphere, width=128, height=96)

    def frame(index):
        # Pictures and, every other frame, every buffer: the arrays handed to Python must be
        # freed with them.
        image = renderer.render(camera, mode="surface", buffers=index % 2 == 0)
        if index % 2 == 0:
            renderer.buffers()
        renderer.timings()
        return image

    for index in range(20):  # shaders, images and driver caches are made on the first frames
        frame(index)
    gc.collect()
    before = resident_bytes()
    for index in range(500):
        frame(index)
    gc.collect()
    growth = resident_bytes() - before
    # Keeping one picture per frame would add 500 × 36 kB = 18 MB, one frame's buffers
    # 250 × 540 kB = 135 MB; 4 MB leaves room for the allocator's and the driver's own
    # fluctuation.
    assert growth < 4 << 20, f"resident memory grew by {growth / 2**20:.1f} MiB"
    print(f"resident memory growth over 500 renders: {growth / 2**20:.2f} MiB")
