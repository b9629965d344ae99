#!/usr/bin/python3
"""A comparison strip of one scan: 1-pixel points, splats, the reconstructed surface and the
surface with subsurface scattering, side by side with their names, from one camera.

    PYTHONPATH=build/python python3 examples/compare_strip.py [SCAN] [-o strip.png]

SCAN is any file subscan reads or synthetic:NAME (default synthetic:sculpture, a virtual scan
of a marble sculpture). Needs numpy and PIL (Debian's python3-numpy and python3-pil).
"""
import argparse

import numpy as np
from PIL import Image, ImageDraw

import subscan

PANELS = [("points", "points (1 px)"), ("splats", "splats"), ("surface", "surface"),
          ("sss", "subsurface scattering")]


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scan", nargs="?", default="synthetic:sculpture")
    parser.add_argument("-o", "--output", default="strip.png")
    parser.add_argument("--width", type=int, default=480)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--yaw", type=float, default=30.0)
    parser.add_argument("--pitch", type=float, default=20.0)
    parser.add_argument("--material", default="marble-jimenez",
                        help="the sss panel's material (see subscan.materials())")
    options = parser.parse_args()

    cloud = subscan.load(options.scan)
    camera = subscan.Camera.orbit(cloud, yaw=options.yaw, pitch=options.pitch,
                                  width=options.width, height=options.height)
    settings = subscan.Settings(raster={"point_size": 3},
                                scattering={"material": options.material})
    renderer = subscan.Renderer(cloud)
    pictures = []
    for mode, label in PANELS:
        picture = Image.fromarray(renderer.render(camera, mode=mode, settings=settings))
        ImageDraw.Draw(picture).text((10, 10), label, fill=(255, 255, 255))
        pictures.append(np.asarray(picture))
        milliseconds = sum(renderer.timings().values())
        print(f"{label}: {milliseconds:.0f} ms")
    Image.fromarray(np.concatenate(pictures, axis=1)).save(options.output)
    print(f"{options.output}: {len(cloud):,} points of {options.scan}")


if __name__ == "__main__":
    main()
