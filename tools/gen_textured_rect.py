#!/usr/bin/env python3
"""Writes the textured-rect stages of BENCHMARKS.md ("Small textured rects' irradiance on the
device", issue 24 item 3): for each size N given, OUT_DIR/texN.png (an N × N 8-bit RGB texture
of seeded random texels in 40..239) and OUT_DIR/rectN.usda (a 2 × 1 RectLight of intensity 5,
2 units above the floor, facing down, with that texture).

    python3 tools/gen_textured_rect.py OUT_DIR N [N ...]

Then, e.g.: luxeval falloff OUT_DIR/rect64.usda --origin -3,0,3 --u 6,0,0 --v 0,0,-6
--res 32,32 -o map.exr --device cpu [--tolerance 1e-9].

Plain Python (zlib for the PNG), no other packages; the output is deterministic.
"""

import random
import struct
import sys
import zlib
from pathlib import Path


def png(path: Path, n: int, seed: int) -> None:
    rng = random.Random(seed)
    raw = b"".join(
        b"\x00" + bytes(rng.randrange(40, 240) for _ in range(3 * n)) for _ in range(n)
    )

    def chunk(tag: bytes, data: bytes) -> bytes:
        crc = zlib.crc32(tag + data) & 0xFFFFFFFF
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", crc)

    header = struct.pack(">IIBBBBB", n, n, 8, 2, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(raw))
        + chunk(b"IEND", b"")
    )


STAGE = """#usda 1.0
(
    upAxis = "Y"
)

def RectLight "Rect"
{{
    float inputs:width = 2
    float inputs:height = 1
    float inputs:intensity = 5
    asset inputs:texture:file = @tex{n}.png@
    double3 xformOp:translate = (0, 2, 0)
    float xformOp:rotateX = -90
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateX"]
}}
"""


def main() -> None:
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    for arg in sys.argv[2:]:
        n = int(arg)
        if not 1 <= n <= 4096:
            sys.exit(f"size {arg}: expected 1 to 4096")
        png(out / f"tex{n}.png", n, n)
        (out / f"rect{n}.usda").write_text(STAGE.format(n=n))


if __name__ == "__main__":
    main()
