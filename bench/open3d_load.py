#!/usr/bin/python3
"""Times Open3D's read_point_cloud on the given files (Debian's python3-open3d), for the loading
comparison in bench/README.md. Prints one line per file: name, points, median ms of N runs."""
import statistics
import sys
import time

import open3d as o3d

runs = 7
for path in sys.argv[1:]:
    times = []
    points = 0
    for _ in range(runs):
        start = time.perf_counter()
        cloud = o3d.io.read_point_cloud(path)
        times.append((time.perf_counter() - start) * 1000.0)
        points = len(cloud.points)
    print(f"{path}\topen3d {o3d.__version__}\t{points} points\tmedian {statistics.median(times):.1f} ms")
