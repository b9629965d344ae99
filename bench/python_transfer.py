#!/usr/bin/python3
"""What passing N points from numpy to a subscan.Renderer costs, against one memcpy of the
same bytes (the target: at most 2x that memcpy), for bench/README.md.

    PYTHONPATH=build/python python3 bench/python_transfer.py [--points 10000000] [--runs 9]

Times, the fastest of --runs (the machine is shared; the median is printed beside it):
  memcpy (new)   the arrays copied into new memory (numpy's copy(): malloc, huge-page advice,
                 memcpy); the kernel zeroes each fresh page on first touch, which any copy into
                 new memory pays
  memcpy (warm)  ctypes.memmove into arrays already touched: the floor no new array reaches
  Cloud          subscan.Cloud(points, colors): validation, bounds, float32 positions around
                 the middle, colours to RGBA8 (what the library's readers build)
  Renderer       subscan.Renderer(cloud) once the cloud's spacing is known: a GL context of its
                 own and the points on the GPU (read in place where the driver allows)
  to Renderer    Cloud + Renderer: the points' whole way from numpy into a renderer
  spacing        cloud.spacing, the estimate of h that every renderer of the cloud shares,
                 once per cloud; the cloud's first Renderer also decides from its sample
                 whether the local spacing is needed (and estimates it, if so)
"""
import argparse
import ctypes
import os
import platform
import statistics
import sys
import time

import numpy as np

import subscan


def timed(call, runs):
    """(fastest, median) seconds of `runs` calls."""
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return min(times), statistics.median(times)


def memcpy(sources, targets):
    for source, target in zip(sources, targets):
        ctypes.memmove(target.ctypes.data, source.ctypes.data, source.nbytes)


def cpu_name():
    try:
        with open("/proc/cpuinfo") as cpuinfo:
            for line in cpuinfo:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--points", type=int, default=10_000_000)
    parser.add_argument("--runs", type=int, default=9)
    options = parser.parse_args()
    count, runs = options.points, options.runs

    rng = np.random.default_rng(1)
    # A scan-like cloud far from the origin (UTM-sized): the offset must be kept in double.
    points64 = rng.uniform(0.0, 100.0, size=(count, 3)) + np.array([5.0e5, 5.0e6, 0.0])
    points32 = points64.astype(np.float32)
    colors = rng.integers(0, 256, size=(count, 3), dtype=np.uint8)
    print(f"{count:,} points, {cpu_name()}, {os.cpu_count()} CPUs, numpy {np.__version__}, "
          f"subscan {subscan.__version__}")

    def milliseconds(pair):
        return f"{pair[0] * 1e3:.1f} ms (median {pair[1] * 1e3:.1f})"

    cloud_times = {}
    for name, points in (("float64", points64), ("float32", points32)):
        sources = (points, colors)
        targets = tuple(np.empty_like(array) for array in sources)
        megabytes = sum(array.nbytes for array in sources) / 1e6
        memcpy(sources, targets)  # touch the targets' pages once, as a reused buffer would be
        warm = timed(lambda: memcpy(sources, targets), runs)
        new = timed(lambda: [array.copy() for array in sources], runs)
        cloud_time = timed(lambda: subscan.Cloud(points, colors=colors), runs)
        cloud_times[name] = (cloud_time, new, warm)
        print(f"{name} points + uint8 colours ({megabytes:.0f} MB):")
        print(f"  memcpy (new)  {milliseconds(new)}")
        print(f"  memcpy (warm) {milliseconds(warm)}")
        print(f"  Cloud         {milliseconds(cloud_time)} = {cloud_time[0] / new[0]:.2f}x memcpy "
              f"(new), {cloud_time[0] / warm[0]:.2f}x memcpy (warm)")

    cloud = subscan.Cloud(points64, colors=colors)
    start = time.perf_counter()
    spacing = cloud.spacing
    spacing_time = time.perf_counter() - start
    start = time.perf_counter()
    subscan.Renderer(cloud).close()  # the first renderer also decides on the local spacing
    first_renderer_time = time.perf_counter() - start

    def make_renderer():
        subscan.Renderer(cloud).close()

    renderer_time = timed(make_renderer, runs)
    print(f"Renderer(cloud): {milliseconds(renderer_time)} (its own GL context, the points)")
    worst = 0.0
    for name, (cloud_time, new, warm) in cloud_times.items():
        total = cloud_time[0] + renderer_time[0]
        worst = max(worst, total / new[0])
        print(f"{name} to Renderer: {total * 1e3:.1f} ms = {total / new[0]:.2f}x memcpy (new), "
              f"{total / warm[0]:.2f}x memcpy (warm)")
    print(f"spacing h = {spacing:.4g}: {spacing_time * 1e3:.0f} ms; the cloud's first Renderer "
          f"{first_renderer_time * 1e3:.0f} ms (it also decides on the local spacing; both once "
          f"per cloud, shared by its renderers)")
    with subscan.Renderer(cloud) as renderer:
        print(f"OpenGL: {renderer.opengl}")
    print(f"worst numpy-to-Renderer / memcpy (new) ratio: {worst:.2f} (target <= 2)")
    return 0 if worst <= 2.0 else 1


if __name__ == "__main__":
    sys.exit(main())
