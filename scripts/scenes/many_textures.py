#!/usr/bin/env python3
"""Writes a load benchmark: a rippled sheet of about a million triangles in 30 bands, each band
its own MTL material with its own 1024² PNG colour map (stripes and checks in its own colours).
Real files have many large textures and big meshes; this one measures reading and building them.

    python3 scripts/scenes/many_textures.py OUT_DIR [TRIANGLES] [TEXTURES] [SIZE]

Writes OUT_DIR/many_textures.obj, .mtl and textures/t00.png … (standard library only).
"""
import math
import struct
import sys
import zlib
from pathlib import Path


def png(path, size, colours, period):
    """An RGB PNG of `size`² texels: checks of `period` texels in the two colours."""
    a, b = bytes(colours[0]), bytes(colours[1])
    half = (size // period) // 2 + 1
    row_a = ((a * period + b * period) * half)[: 3 * size]
    row_b = ((b * period + a * period) * half)[: 3 * size]
    raw = b"".join(b"\x00" + (row_a if (y // period) % 2 == 0 else row_b) for y in range(size))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out = Path(sys.argv[1])
    triangles = int(sys.argv[2]) if len(sys.argv) > 2 else 1_000_000
    textures = int(sys.argv[3]) if len(sys.argv) > 3 else 30
    size = int(sys.argv[4]) if len(sys.argv) > 4 else 1024
    (out / "textures").mkdir(parents=True, exist_ok=True)
    for i in range(textures):
        hue = i / textures
        c0 = [int(255 * (0.5 + 0.5 * math.cos(2 * math.pi * (hue + k / 3)))) for k in range(3)]
        c1 = [255 - v // 2 for v in c0]
        png(out / "textures" / f"t{i:02d}.png", size, (c0, c1), 8 + 4 * (i % 5))
    with open(out / "many_textures.mtl", "w") as f:
        for i in range(textures):
            f.write(f"newmtl m{i:02d}\nKd 1 1 1\nKs 0 0 0\nmap_Kd textures/t{i:02d}.png\n\n")
    # A grid of n × n quads (two triangles each) over [-1, 1]², gently rippled.
    n = max(2, int(math.sqrt(triangles / 2)))
    lines = ["mtllib many_textures.mtl\n"]
    for j in range(n + 1):
        y = -1 + 2 * j / n
        for i in range(n + 1):
            x = -1 + 2 * i / n
            z = 0.02 * math.sin(9 * x) * math.cos(7 * y)
            lines.append(f"v {x:.5f} {y:.5f} {z:.5f}\nvt {i / n * 4:.5f} {j / n * 4:.5f}\n")
    band = max(1, n // textures)
    for j in range(n):
        if j % band == 0:
            lines.append(f"usemtl m{min(j // band, textures - 1):02d}\n")
        for i in range(n):
            a = j * (n + 1) + i + 1
            b, c, d = a + 1, a + n + 2, a + n + 1
            lines.append(f"f {a}/{a} {b}/{b} {c}/{c}\nf {a}/{a} {c}/{c} {d}/{d}\n")
    (out / "many_textures.obj").write_text("".join(lines))
    print(f"{out / 'many_textures.obj'}: {2 * n * n} triangles, {textures} textures of {size}²")


if __name__ == "__main__":
    main()
