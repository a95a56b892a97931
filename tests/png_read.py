#!/usr/bin/python3
"""Reads the PNG file written by sphere's renderer back with Pillow and checks it.

usage: /usr/bin/python3 tests/png_read.py --writer EXE DIR

DIR is emptied and `EXE DIR` (tests/png_writer_main.cpp) writes DIR/frame.png and the same
picture's raw RGB bytes, DIR/frame.rgb. The PNG file must be a 120 x 90 8-bit RGB image whose
decoded pixels equal the raw bytes, with the text chunks naming the field (vel) and the colour
range (lower_cutoff 0, max_val 12), and must hold the three spheres' colours at their centres.

Exit status: 0 when everything matches, 1 on any mismatch (each is printed), 77 when this Python
cannot import Pillow (Debian's python3-pil serves /usr/bin/python3 only), 2 on bad usage.
"""

import argparse
import os
import shutil
import subprocess
import sys

try:
    from PIL import Image
except ImportError as error:
    print(f"SKIP: {sys.executable} cannot import Pillow ({error}); install python3-pil")
    sys.exit(77)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--writer", required=True)
    parser.add_argument("dir")
    args = parser.parse_args()
    shutil.rmtree(args.dir, ignore_errors=True)
    os.makedirs(args.dir)
    subprocess.run([args.writer, args.dir], check=True)

    problems = []
    with Image.open(os.path.join(args.dir, "frame.png")) as image:
        image.load()
        if image.format != "PNG" or image.mode != "RGB" or image.size != (120, 90):
            problems.append(f"format {image.format}, mode {image.mode}, size {image.size}: expected PNG, RGB, (120, 90)")
        with open(os.path.join(args.dir, "frame.rgb"), "rb") as raw:
            expected = raw.read()
        if image.tobytes() != expected:
            problems.append("the decoded pixels differ from the renderer's bytes")
        text = dict(image.text)
        for key, value in {"Software": "sphere", "sphere field": "vel", "sphere lower_cutoff": "0",
                           "sphere max_val": "12"}.items():
            if text.get(key) != value:
                problems.append(f"text chunk {key!r} = {text.get(key)!r}, expected {value!r}")
        # The spheres' centres, pixels (36, 33), (86, 60) and (63, 11) at 12 pixels a metre: speeds
        # 0, 5 and 10 of 12 are dark blue, cyan-green and red-orange (render/colour_map.cuh).
        pixels = image.load()
        for (x, y), (kind, test) in {
            (36, 33): ("dark blue", lambda r, g, b: b > 60 and r == 0 and g == 0),
            (86, 60): ("cyan-green", lambda r, g, b: g > r and g > b and b > r),
            (63, 11): ("red-orange", lambda r, g, b: r > 2 * g and b == 0),
        }.items():
            if not test(*pixels[x, y]):
                problems.append(f"pixel ({x}, {y}) = {pixels[x, y]}: expected {kind}")
        if pixels[0, 89] != (255, 255, 255):
            problems.append(f"pixel (0, 89) = {pixels[0, 89]}: expected the white background")
    for p in problems:
        print(p)
    print(f"png_read: {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
