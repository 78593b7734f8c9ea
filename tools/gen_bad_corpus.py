#!/usr/bin/env python3
"""Writes the bad-input corpus tests/data/bad/ (one file per kind of bad input; tests/bad_inputs.rs
runs the CLI on each). Text stages are written by hand here so that each says exactly what it
tests; the binary ones (.usdc, .usdz) and the NumPy ones are written by Pixar's usd-core and NumPy
themselves, so the readers are tested against the real formats. Needs numpy and usd-core:

    python3 -m venv /tmp/v && /tmp/v/bin/pip install numpy usd-core
    /tmp/v/bin/python tools/gen_bad_corpus.py

Output is deterministic (the .usdz timestamps are pinned)."""
import os
import struct
import zipfile

import numpy as np
from pxr import Sdf, Usd, UsdGeom, UsdLux

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data", "bad")
os.makedirs(OUT, exist_ok=True)
for f in os.listdir(OUT):
    os.remove(os.path.join(OUT, f))


def text(name, body):
    with open(os.path.join(OUT, name), "w") as f:
        f.write("#usda 1.0\n" + body)


def light(name="L", ty="SphereLight", attrs="", meta=""):
    meta = f" (\n    {meta}\n)" if meta else ""
    return f'\ndef {ty} "{name}"{meta}\n{{\n{attrs}}}\n'


# --- good inputs the bad ones are paired with ---------------------------------------------------
text("ok.usda", '(\n    upAxis = "Y"\n)\n'
     + light("L", attrs="    float inputs:radius = 0.5\n    float inputs:intensity = 10\n")
     + light("R", "RectLight", "    float inputs:intensity = 5\n"
             "    double3 xformOp:translate = (0, 3, 0)\n"
             '    uniform token[] xformOpOrder = ["xformOp:translate"]\n'))
dirs = np.array([[0, -1, 0], [0.3, -0.9, 0.1], [1, 0, 0], [0, 0, -1]], dtype="<f4")
np.save(os.path.join(OUT, "dirs.npy"), dirs)
np.save(os.path.join(OUT, "dirs5.npy"), np.vstack([dirs, dirs[:1]]))
np.save(os.path.join(OUT, "points.npy"), np.array([[0, 3, 0], [1, 2, 0], [0, -2, 1], [4, 0, 0]], dtype="<f4"))
np.save(os.path.join(OUT, "normals.npy"), np.array([[0, 1, 0]] * 4, dtype="<f4"))

# --- composition: cycles, depth, chains, size ---------------------------------------------------
text("self_inherit.usda", light(meta="inherits = </L>"))
text("class_inherits_itself.usda", '\nclass "C" (\n    inherits = </C>\n)\n{\n}\n' + light(meta="inherits = </C>"))
text("inherit_ancestor.usda", '\ndef Xform "A"\n{' + light("B", meta="inherits = </A>").replace("\n", "\n    ") + "\n}\n")
text("inherit_descendant.usda", '\ndef SphereLight "L" (\n    inherits = </L/C>\n)\n{\n    def "C"\n    {\n    }\n}\n')
text("reference_self.usda", light(meta="references = </L>"))
text("specialize_self.usda", light(meta="specializes = </L>"))
text("reference_cycle_a.usda", '(\n    defaultPrim = "A"\n)\n' + light("A", meta="references = @reference_cycle_b.usda@"))
text("reference_cycle_b.usda", '(\n    defaultPrim = "B"\n)\n' + light("B", meta="references = @reference_cycle_a.usda@"))
text("sublayer_cycle_a.usda", "(\n    subLayers = [@sublayer_cycle_b.usda@]\n)\n" + light("A"))
text("sublayer_cycle_b.usda", "(\n    subLayers = [@sublayer_cycle_a.usda@]\n)\n" + light("B"))


def nested(name, levels):
    """A light under `levels - 1` Xforms: a namespace `levels` deep."""
    lines = ['def Xform "p%d" {' % i for i in range(levels - 1)]
    lines.append('def SphereLight "L" {\n}')
    lines += ["}"] * (levels - 1)
    text(name, "\n" + "\n".join(lines) + "\n")


nested("deep_10000.usda", 10000)
nested("deep_1001.usda", 1001)
nested("deep_150.usda", 150)


def chain(name, arcs):
    """A light at the end of a chain of `arcs` internal references from /R0."""
    body = "".join('\ndef "R%d" (\n    references = </R%d>\n)\n{\n}\n' % (i, i + 1) for i in range(arcs))
    text(name, body + light("R%d" % arcs, attrs="    float inputs:intensity = 3\n"))


chain("chain_98.usda", 98)
chain("chain_99.usda", 99)
chain("chain_150.usda", 150)


def explode(name, levels, fan):
    """Level k holds `fan` children, each referencing level k + 1: fan ** levels prims."""
    body = ""
    for k in range(levels):
        body += '\ndef Xform "L%d"\n{\n' % k
        for j in range(fan):
            if k + 1 < levels:
                body += '    def "c%d" (\n        references = </L%d>\n    )\n    {\n    }\n' % (j, k + 1)
            else:
                body += '    def SphereLight "c%d"\n    {\n    }\n' % j
        body += "}\n"
    text(name, body)


explode("prim_explosion.usda", 8, 10)
explode("prims_120.usda", 2, 10)

# A class inheriting itself, as usd-core's crate writer writes it.
layer = Sdf.Layer.CreateNew(os.path.join(OUT, "class_inherits_itself.usdc"))
stage = Usd.Stage.Open(layer)
cls = stage.CreateClassPrim("/C")
cls.GetInherits().AddInherit("/C")
UsdLux.SphereLight.Define(stage, "/L").GetPrim().GetInherits().AddInherit("/C")
layer.Save()

# --- LightAPI on prims that are not light types -------------------------------------------------
text("lightapi_on_xform.usda", '\ndef Xform "Rig" (\n    prepend apiSchemas = ["LightAPI"]\n)\n{\n    float inputs:intensity = 4\n}\n')
text("lightapi_on_unknown_type.usda", '\ndef FancyLight "Fancy" (\n    prepend apiSchemas = ["LightAPI"]\n)\n{\n}\n')
text("lightapi_on_untyped.usda", '\ndef "Bare" (\n    prepend apiSchemas = ["LightAPI"]\n)\n{\n}\n')

# --- finite values whose results do not fit float32 ---------------------------------------------
text("exposure_200.usda", light(attrs="    float inputs:exposure = 200\n"))
text("intensity_1e39.usda", light(attrs="    double inputs:intensity = 1e39\n"))
text("color_1e39.usda", light(attrs="    color3d inputs:color = (1e39, 1, 1)\n"))
text("normalize_tiny.usda", light(attrs="    bool inputs:normalize = 1\n    double inputs:radius = 1e-30\n"))
text("radius_1e19.usda", light(attrs="    double inputs:radius = 1e19\n"))
text("translate_1e19.usda", light(attrs="    double3 xformOp:translate = (1e19, 0, 0)\n"
                                       '    uniform token[] xformOpOrder = ["xformOp:translate"]\n'))
text("domes_sum_overflows.usda", "".join(light("D%d" % i, "DomeLight", "    double inputs:intensity = 1e38\n") for i in range(4)))
text("point_light.usda", light(attrs="    bool treatAsPoint = 1\n    float inputs:radius = 1\n"))
np.save(os.path.join(OUT, "point_on_light.npy"), np.array([[0, 1e-30, 0]], dtype="<f4"))
np.save(os.path.join(OUT, "normal_down.npy"), np.array([[0, -1, 0]], dtype="<f4"))
np.save(os.path.join(OUT, "dirs_f64_huge.npy"), dirs.astype("<f8") * 1e300)
np.save(os.path.join(OUT, "dirs_f32_subnormal.npy"), dirs * np.float32(1e-40))
np.save(os.path.join(OUT, "dirs_f32_huge.npy"), dirs * np.float32(3e38))
# Four rows, to pair with dirs.npy: the row counts are compared from the headers, before any row.
np.save(os.path.join(OUT, "points_f64_huge.npy"), np.array([[0, 0, 0], [1e300, 0, 0], [0, 0, 0], [0, 0, 0]], dtype="<f8"))

# --- counts and sizes ---------------------------------------------------------------------------


def npy_raw(name, header, data=b"", version=1):
    h = header.encode()
    pad = 64 - (10 + len(h) + 1) % 64
    h = h + b" " * pad + b"\n"
    size = struct.pack("<H", len(h)) if version == 1 else struct.pack("<I", len(h))
    with open(os.path.join(OUT, name), "wb") as f:
        f.write(b"\x93NUMPY" + bytes([version, 0]) + size + h + data)


# rows × 3 × 4 = 2^64 + 12: wraps to 12 bytes, which the file holds.
npy_raw("npy_rows_wrap.npy", "{'descr': '<f4', 'fortran_order': False, 'shape': (%d, 3), }" % ((2**64 + 12) // 12), b"\0" * 12)
npy_raw("npy_more_rows_than_data.npy", "{'descr': '<f4', 'fortran_order': False, 'shape': (1000, 3), }", dirs.tobytes())
npy_raw("npy_trailing_data.npy", "{'descr': '<f4', 'fortran_order': False, 'shape': (4, 3), }", dirs.tobytes() + b"\0" * 8)
with open(os.path.join(OUT, "npy_huge_header.npy"), "wb") as f:
    f.write(b"\x93NUMPY\x02\x00" + struct.pack("<I", 0xFFFFFFF0) + b"{'descr': '<f4'")
npy_raw("npy_header_code.npy", "{'descr': '<f4', 'fortran_order': False, 'shape': (4, 3), 'x': __import__('os')}", dirs.tobytes())
np.save(os.path.join(OUT, "npy_int.npy"), dirs.astype("<i4"))
np.save(os.path.join(OUT, "npy_object.npy"), np.array([[1, 2, 3]], dtype=object), allow_pickle=True)
np.save(os.path.join(OUT, "npy_3d.npy"), np.zeros((2, 2, 3), dtype="<f4"))
with open(os.path.join(OUT, "npy_not_numpy.npy"), "wb") as f:
    f.write(b"PK\x03\x04 this is a zip, not an array")
text("references_big_layer.usda", light(meta="references = @big_layer.usda@</L>"))
text("big_layer.usda", light(attrs="".join("    custom float pad%d = %d\n" % (i, i) for i in range(200))))

# --- values of the wrong type, or NaN -----------------------------------------------------------
text("color_int3.usda", light(attrs="    int3 inputs:color = (1, 0, 0)\n"))
text("intensity_int.usda", light(attrs="    int inputs:intensity = 5\n"))
text("intensity_string.usda", light(attrs='    string inputs:intensity = "5"\n'))
text("normalize_string.usda", light(attrs='    string inputs:normalize = "yes"\n'))
text("start_time_nan.usda", "(\n    startTimeCode = nan\n)\n" + light())
text("start_time_inf.usda", "(\n    startTimeCode = inf\n)\n" + light())
text("intensity_nan.usda", light(attrs="    float inputs:intensity = nan\n"))
text("intensity_nan_sample.usda", light(attrs="    float inputs:intensity.timeSamples = {\n        0: nan,\n        10: 1,\n    }\n"))

# --- messages that must name the file -----------------------------------------------------------
text("zero_size_normalize.usda", light(attrs="    bool inputs:normalize = 1\n    float inputs:radius = 0\n"))
text("negative_radius.usda", light(attrs="    float inputs:radius = -1\n"))
text("singular_scale.usda", light(attrs="    float3 xformOp:scale = (1, 0, 1)\n"
                                        '    uniform token[] xformOpOrder = ["xformOp:scale"]\n'))
np.save(os.path.join(OUT, "dirs_nan.npy"), np.array([[0, -1, 0], [1, 0, 0], [np.nan, 0, 0]], dtype="<f4"))
np.save(os.path.join(OUT, "dirs_zero_row.npy"), np.array([[0, -1, 0], [0, 0, 0]], dtype="<f8"))
np.save(os.path.join(OUT, "points_inf.npy"), np.array([[np.inf, 0, 0]] * 4, dtype="<f4"))
np.save(os.path.join(OUT, "normals_zero.npy"), np.array([[0, 1, 0], [0, 1, 0], [0, 0, 0], [0, 1, 0]], dtype="<f4"))

# --- malformed files ----------------------------------------------------------------------------
text("malformed.usda", '\ndef SphereLight "L"\n{\n    float inputs:intensity = \n}\n')
text("missing_reference.usda", light(meta="references = @does_not_exist.usda@</L>"))
with open(os.path.join(OUT, "empty.usda"), "wb"):
    pass
with open(os.path.join(OUT, "not_usd.usda"), "w") as f:
    f.write("this is not a USD file\n")
good = Sdf.Layer.CreateNew(os.path.join(OUT, "_tmp.usdc"))
s = Usd.Stage.Open(good)
UsdLux.SphereLight.Define(s, "/L").CreateIntensityAttr(2.0)
UsdGeom.Xform.Define(s, "/W")
good.Save()
raw = open(os.path.join(OUT, "_tmp.usdc"), "rb").read()
os.remove(os.path.join(OUT, "_tmp.usdc"))
with open(os.path.join(OUT, "truncated.usdc"), "wb") as f:
    f.write(raw[: len(raw) // 2])
bad_toc = bytearray(raw)
bad_toc[16:24] = struct.pack("<Q", 2**62)  # the table-of-contents offset
with open(os.path.join(OUT, "toc_offset.usdc"), "wb") as f:
    f.write(bad_toc)
# usdz: a stored layer with its bytes corrupted; and one whose layer is deflated (not allowed).
with open(os.path.join(OUT, "layer.usda"), "w") as f:
    f.write('#usda 1.0\n\ndef SphereLight "L"\n{\n}\n')
for name, method, payload in [
    ("corrupt.usdz", zipfile.ZIP_STORED, raw[:64] + b"\xff" * 64 + raw[128:]),
    ("deflated.usdz", zipfile.ZIP_DEFLATED, open(os.path.join(OUT, "layer.usda"), "rb").read()),
]:
    with zipfile.ZipFile(os.path.join(OUT, name), "w") as z:
        info = zipfile.ZipInfo("root.usdc" if name == "corrupt.usdz" else "root.usda", (2026, 1, 1, 0, 0, 0))
        info.compress_type = method
        z.writestr(info, payload)
os.remove(os.path.join(OUT, "layer.usda"))

# IES profiles (LM-63): no TILT line, a count that is not an integer, a TILT file that does not
# exist, a file that ends inside the candela values; stages whose light names a missing profile
# and the truncated one.
IES_HEAD = "IESNA:LM-63-2002\n"
IES_BODY = "1 -1 1 3 1 1 2 0 0 0\n1 1 100\n0 45 90\n0\n100 50 0\n"
for name, body in [
    ("ies_no_tilt.ies", IES_HEAD + "[TEST] x\n" + IES_BODY),
    ("ies_bad_count.ies", IES_HEAD + "TILT=NONE\n" + IES_BODY.replace("1 3 1", "1 3.5 1", 1)),
    ("ies_tilt_missing.ies", IES_HEAD + "TILT=nothere.tilt\n" + IES_BODY),
    ("ies_truncated.ies", IES_HEAD + "TILT=NONE\n" + IES_BODY[: -len(" 0\n")] + "\n"),
]:
    with open(os.path.join(OUT, name), "w") as f:
        f.write(body)
for name, profile in [("ies_missing_file.usda", "missing.ies"), ("ies_truncated.usda", "ies_truncated.ies")]:
    text(name, '\ndef SphereLight "L" (\n    prepend apiSchemas = ["ShapingAPI"]\n)\n{\n'
         f"    asset inputs:shaping:ies:file = @{profile}@\n}}\n")

# A valid profile whose candela values do not fit float32 (1e39), used with and without
# ies:normalize: both paths refuse it, naming the light, the attribute and the file.
with open(os.path.join(OUT, "ies_huge.ies"), "w") as f:
    f.write(IES_HEAD + "TILT=NONE\n" + IES_BODY.replace("100 50 0", "1e39 5e38 0"))
for name, extra in [("ies_huge.usda", ""), ("ies_huge_normalized.usda", "    bool inputs:shaping:ies:normalize = 1\n")]:
    text(name, '\ndef SphereLight "L" (\n    prepend apiSchemas = ["ShapingAPI"]\n)\n{\n'
         f"    asset inputs:shaping:ies:file = @ies_huge.ies@\n{extra}}}\n")

# Zero-size lights beside an ordinary one (DESIGN.md §2): a disk scaled flat by an animator and a
# DCC's point light (a radius-0 treatAsPoint sphere with normalize): both evaluated with a
# warning, never refusing the stage.
text("zero_size_beside_others.usda",
     '\ndef DiskLight "Hidden"\n{\n    float3 xformOp:scale = (1, 0, 1)\n'
     '    uniform token[] xformOpOrder = ["xformOp:scale"]\n}\n'
     '\ndef SphereLight "Point"\n{\n    bool inputs:normalize = 1\n    float inputs:radius = 0\n'
     '    float inputs:intensity = 8\n    bool treatAsPoint = 1\n}\n'
     '\ndef RectLight "Key"\n{\n    float inputs:intensity = 5\n}\n')

# Texture tokens the schema does not allow: the queries refuse the dome (exit 2) naming the prim
# and the attribute, instead of skipping it.
text("dome_bad_format.usda", '\ndef DomeLight "D"\n{\n    asset inputs:texture:file = @sky.exr@\n'
     '    token inputs:texture:format = "cube"\n}\n')
text("dome1_bad_pole_axis.usda", '\ndef DomeLight_1 "D"\n{\n    asset inputs:texture:file = @sky.exr@\n'
     '    uniform token poleAxis = "X"\n}\n')

print(len(os.listdir(OUT)), "files in", os.path.normpath(OUT))
