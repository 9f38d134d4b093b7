#!/usr/bin/env python3
"""Writes a synthetic "studio" environment (equirectangular EXR) for trying IBL settings under a
sky none of them was tuned on: a dim room, a warm floor, an overhead softbox and two narrow
strip lights just above the horizon (one bright and warm, one dimmer and cool). Nothing in it is
random, so the file is the same on every run.

    pip install mitsuba numpy        # mitsuba writes the EXR (scripts/mitsuba_crosscheck.py uses it too)
    python3 scripts/studio_sky.py /tmp/studio.exr
    cargo run -p harness -- sweep --scene ibl --knob ibl --environment /tmp/studio.exr

docs/renderer.md records what the IBL sweep measured under it (2026-11-26).
"""

import sys

import mitsuba as mi
import numpy as np


def studio(width=512, height=256):
    """RGB radiance, rows from the zenith (theta 0) down, columns over phi 0..2 pi."""
    theta = (np.arange(height) + 0.5) / height * np.pi
    phi = (np.arange(width) + 0.5) / width * 2.0 * np.pi
    t, p = np.meshgrid(theta, phi, indexing="ij")
    image = np.full((height, width, 3), 0.04, np.float32)
    image[t > np.pi / 2] = (0.12, 0.09, 0.06)  # floor
    image[t < np.radians(25)] = (6.0, 6.0, 6.0)  # overhead softbox
    for centre, colour in ((0.6, (30.0, 28.0, 25.0)), (3.8, (8.0, 10.0, 14.0))):
        across = np.abs((p - centre + np.pi) % (2.0 * np.pi) - np.pi) < np.radians(6)
        band = (t > np.radians(50)) & (t < np.radians(85))
        image[across & band] = colour
    return image


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: studio_sky.py OUT.exr")
    mi.set_variant("scalar_rgb")
    mi.Bitmap(studio()).write(sys.argv[1])
    print(f"wrote {sys.argv[1]}")


if __name__ == "__main__":
    main()
