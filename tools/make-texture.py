#!/usr/bin/env python3
"""Writes the generated texture images of scenes/assets/ as 8-bit sRGB PNG files, with nothing
but the standard library: tools/make-texture.py scenes/assets
  tiles.png   256 x 256: 8 x 8 tiles of alternating light and dark grey with thin mortar lines
              and a red mark in each tile's bottom-left corner, so orientation shows
  bumps.png   128 x 128: a grey height map of rounded cobbles (white high, black low)
  sky.hdr     128 x 64 Radiance HDR (linear, uncompressed), an equirectangular environment: a
              blue sky brightening to the horizon, a brown ground, and a small bright sun
              25 degrees up at azimuth phi = 60 degrees (u = 1/6), for scenes/assets/sky.xml
"""
import math
import struct
import sys
import zlib
from pathlib import Path


def write_png(path, width, height, pixel):
    rows = bytearray()
    for y in range(height):  # top row first, as PNG stores them
        rows.append(0)
        for x in range(width):
            rows.extend(pixel(x, height - 1 - y))  # pixel() takes y from the bottom
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))
    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(rows), 9))
    png += chunk(b"IEND", b"")
    Path(path).write_bytes(png)


def write_hdr(path, width, height, pixel):
    header = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (height, width)
    data = bytearray(header)
    for y in range(height):  # top row first
        for x in range(width):
            colour = pixel(x, height - 1 - y, width, height)
            m = max(colour)
            if m < 1e-32:
                data.extend((0, 0, 0, 0))
                continue
            mantissa, exponent = math.frexp(m)
            scale = mantissa * 256 / m
            data.extend(min(255, int(c * scale)) for c in colour)
            data.append(exponent + 128)
    Path(path).write_bytes(bytes(data))


def sky(x, y, width, height):
    """Radiance along the direction of texel (x, y), y from the bottom (docs/scene-format.md:
    u = phi/2pi with phi = atan2(-dz, dx), v = 1 - theta/pi)."""
    phi = 2 * math.pi * (x + 0.5) / width
    theta = math.pi * (1 - (y + 0.5) / height)
    d = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
    sun_elevation, sun_phi = math.radians(25), math.radians(60)
    s = (math.cos(sun_elevation) * math.cos(sun_phi), math.sin(sun_elevation),
         -math.cos(sun_elevation) * math.sin(sun_phi))
    if sum(a * b for a, b in zip(d, s)) > math.cos(math.radians(4)):
        return (600.0, 540.0, 450.0)
    if d[1] < 0:
        return (0.25, 0.2, 0.15)
    t = d[1]
    return (0.15 + 0.3 * (1 - t), 0.25 + 0.25 * (1 - t), 0.5)


def tiles(x, y):
    size = 32
    tx, ty = x // size, y // size
    fx, fy = x % size, y % size
    if fx < 2 or fy < 2:
        return (60, 55, 50)  # mortar
    if 4 <= fx < 10 and 4 <= fy < 10:
        return (200, 40, 30)  # the bottom-left mark
    return (225, 220, 210) if (tx + ty) % 2 == 0 else (70, 80, 95)


def bumps(x, y):
    size = 16
    fx = (x % size + 0.5) / size - 0.5
    fy = (y % size + 0.5) / size - 0.5
    h = max(0.0, 1 - 4 * (fx * fx + fy * fy))
    v = round(255 * math.sqrt(h))
    return (v, v, v)


if __name__ == "__main__":
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "scenes/assets")
    out.mkdir(parents=True, exist_ok=True)
    write_png(out / "tiles.png", 256, 256, tiles)
    write_png(out / "bumps.png", 128, 128, bumps)
    write_hdr(out / "sky.hdr", 128, 64, sky)
