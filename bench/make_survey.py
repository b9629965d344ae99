#!/usr/bin/env python3
"""Makes a survey-sized LAS file from a small real one: the input tiled N x N side by side.

    bench/make_survey.py ../shared/data/autzen_trim.las 20 /tmp/autzen_20x20.las   # 44 M points
    bench/make_survey.py ../shared/data/autzen_trim.las 60 /tmp/autzen_60x60.las   # 396 M points

Every tile is the input's point records unchanged (every attribute, bit for bit) with X and Y
moved by whole multiples of the input's extent on its integer grid, so the result is a real
survey's density and attributes at any size, and any tile's points are the input's exactly.
The header's counts and bounds are rewritten; the VLRs are copied. Memory stays at one tile's
records whatever N is; the output is written beside its name and renamed when complete.
LAS 1.0-1.3 inputs (32-bit point counts) only.
"""

import math
import os
import struct
import sys

import numpy as np

HEADER_FORMAT = {  # offsets into the LAS 1.0-1.3 public header block
    "version": (24, "<BB"),
    "header_size": (94, "<H"),
    "point_offset": (96, "<I"),
    "point_format": (104, "<B"),
    "record_length": (105, "<H"),
    "legacy_count": (107, "<I"),
    "count_by_return": (111, "<5I"),
    "scale": (131, "<3d"),
    "offset": (155, "<3d"),
    "bounds": (179, "<6d"),  # max x, min x, max y, min y, max z, min z
}


def fail(sentence):
    print(f"make_survey: {sentence}", file=sys.stderr)
    sys.exit(1)


def read_field(header, name):
    offset, layout = HEADER_FORMAT[name]
    values = struct.unpack_from(layout, header, offset)
    return values if len(values) > 1 else values[0]


def main():
    if len(sys.argv) != 4:
        fail("usage: make_survey.py INPUT.las N OUTPUT.las")
    source, tiles_text, target = sys.argv[1:]
    try:
        tiles = int(tiles_text)
    except ValueError:
        tiles = 0
    if tiles < 1:
        fail(f"N must be a whole number of at least 1, not {tiles_text!r}")
    if os.path.exists(target) and os.path.samefile(source, target):
        fail(f"{target}: the output would overwrite the input")
    with open(source, "rb") as file:
        data = file.read()
    if len(data) < 227 or data[:4] != b"LASF":
        fail(f"{source}: not a LAS file (no LASF signature and 227-byte header)")
    header = bytearray(data[: read_field(data, "point_offset")])
    major, minor = read_field(data, "version")
    if (major, minor) > (1, 3):
        fail(f"{source}: LAS {major}.{minor}; only 1.0-1.3 (32-bit counts) are tiled")
    count = read_field(data, "legacy_count")
    length = read_field(data, "record_length")
    start = read_field(data, "point_offset")
    if count == 0 or start + count * length > len(data):
        fail(f"{source}: {count} point records of {length} bytes do not fit the file")
    if count * tiles * tiles > 2**32 - 1:
        fail(f"{count * tiles * tiles} points exceed LAS 1.0-1.3's 32-bit point count")

    records = np.frombuffer(data, dtype=np.uint8, count=count * length, offset=start)
    records = records.reshape(count, length)
    xyz = records[:, :12].copy().view("<i4").reshape(count, 3)
    low, high = xyz.min(axis=0), xyz.max(axis=0)
    # One integer step of gap between tiles, so no two tiles share a position.
    step_x, step_y = int(high[0] - low[0]) + 1, int(high[1] - low[1]) + 1
    last_x = int(high[0]) + (tiles - 1) * step_x
    last_y = int(high[1]) + (tiles - 1) * step_y
    if max(last_x, last_y) > 2**31 - 1:
        fail(f"{tiles} x {tiles} tiles leave LAS's 32-bit integer coordinates")

    scale = read_field(data, "scale")
    offset = read_field(data, "offset")
    bounds = read_field(data, "bounds")
    struct.pack_into("<I", header, 107, count * tiles * tiles)
    by_return = [value * tiles * tiles for value in read_field(data, "count_by_return")]
    struct.pack_into("<5I", header, 111, *by_return)
    struct.pack_into(
        "<6d", header, 179,
        last_x * scale[0] + offset[0], low[0] * scale[0] + offset[0],
        last_y * scale[1] + offset[1], low[1] * scale[1] + offset[1],
        bounds[4], bounds[5])

    partial = f"{target}.partial-{os.getpid()}"
    try:
        with open(partial, "wb") as out:
            out.write(header)
            tile = records.copy()
            moved = tile[:, :12].view("<i4").reshape(count, 3)
            for i in range(tiles):
                for j in range(tiles):
                    moved[:, 0] = xyz[:, 0] + i * step_x
                    moved[:, 1] = xyz[:, 1] + j * step_y
                    out.write(tile.tobytes())
                print(f"\rmake_survey: {(i + 1) * tiles * count:,} points", end="",
                      file=sys.stderr)
        os.replace(partial, target)
    except BaseException:
        if os.path.exists(partial):
            os.remove(partial)
        raise
    print(f"\nmake_survey: {target}: {count * tiles * tiles:,} points, "
          f"{math.ceil(os.path.getsize(target) / 2**20):,} MiB", file=sys.stderr)


if __name__ == "__main__":
    main()
