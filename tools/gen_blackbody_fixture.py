#!/usr/bin/env python3
"""Writes tests/data/blackbody_usdcore.json: colour-temperature multipliers computed by Pixar's
usd-core, the oracle for luxeval's `usd` and `planckian` temperature modes.

    python3 -m venv venv && venv/bin/pip install usd-core
    venv/bin/python tools/gen_blackbody_fixture.py

- usd: pxr.UsdLux.BlackbodyTemperatureAsRgb(T) (the table + Catmull-Rom function, float32).
- planckian: pxr.Gf.Color in LinearRec709 set from the Planckian locus, then divided by its
  Rec.709 luminance, as the OpenUSD reference renderer (hdEmbree) does.
"""
import json
import os

from pxr import Gf, UsdLux

TEMPERATURES = [800, 1000, 1300, 1700, 2000, 2700, 3200, 4000, 4250, 5000, 5600, 6500,
                7000, 8000, 8750, 9500, 10000, 11000, 12000]


def planckian(t):
    c = Gf.Color(Gf.ColorSpace(Gf.ColorSpaceNames.LinearRec709))
    c.SetFromPlanckianLocus(float(t), 1.0)
    rgb = c.GetRGB()
    lum = 0.2126390058715102 * rgb[0] + 0.7151686787677560 * rgb[1] + 0.0721923153607337 * rgb[2]
    return [rgb[i] / lum for i in range(3)]


def main():
    import pxr
    rows = []
    for t in TEMPERATURES:
        usd = UsdLux.BlackbodyTemperatureAsRgb(float(t))
        rows.append({"kelvin": t, "usd": [float(v) for v in usd], "planckian": planckian(t)})
    out = {
        "generator": "tools/gen_blackbody_fixture.py",
        "usd_core_version": ".".join(str(v) for v in pxr.Usd.GetVersion()),
        "rows": rows,
    }
    path = os.path.join(os.path.dirname(__file__), "..", "tests", "data", "blackbody_usdcore.json")
    with open(path, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")
    print(f"wrote {len(rows)} temperatures to {os.path.normpath(path)}")


if __name__ == "__main__":
    main()
