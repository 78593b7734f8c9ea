#!/usr/bin/env python3
"""Writes a big light stage for the scaling measurements of BENCHMARKS.md ("Big stages", issue 24
item 5): N plain SphereLights, PER_GROUP (default 4, or K) to an Xform, every Xform a child of one /World, so
that both the number of prims and the number of siblings under one parent grow with N (the
shape that made the reader quadratic).

    python3 tools/gen_big_stage.py N OUT.usda [--instanced | --own-layers] [--per-group K]

Plain (default): every light is authored in OUT.usda with its own intensity, color and radius.

--instanced: the lights live in one asset layer (OUT's name with `_asset.usda`), PER_GROUP
lights under its defaultPrim; each of the N / PER_GROUP Xforms of OUT.usda references it and is
instanceable, so luxeval reads the lights as instance proxies. N must then be a multiple of
PER_GROUP.

--own-layers: as --instanced, but every Xform references a layer of its own (OUT's name with
`_G<g>.usda`, PER_GROUP lights each) and none is instanceable: N / PER_GROUP distinct layers, the
shape of a set whose every fixture is its own file.

Plain text, no usd-core needed; the output is deterministic. usd-core opens both (check with
`python3 -c 'from pxr import Usd; Usd.Stage.Open("OUT.usda")'`)."""
import os
import sys

PER_GROUP = 4  # set by --per-group


def light(name, i, indent):
    pad = " " * indent
    return (
        f'{pad}def SphereLight "{name}"\n'
        f"{pad}{{\n"
        f"{pad}    color3f inputs:color = ({0.5 + (i % 7) / 14:.4f}, 0.8, {1 - (i % 5) / 10:.4f})\n"
        f"{pad}    float inputs:intensity = {1 + i % 100}\n"
        f"{pad}    float inputs:radius = {0.05 + (i % 3) * 0.05:.2f}\n"
        f"{pad}    double3 xformOp:translate = (0, {(i % PER_GROUP) * 0.5}, 0)\n"
        f'{pad}    uniform token[] xformOpOrder = ["xformOp:translate"]\n'
        f"{pad}}}\n"
    )


def lamp_layer(path, first):
    """Writes an asset layer: PER_GROUP lights (indices first, first + 1, ...) under its
    defaultPrim "Lamp"."""
    with open(path, "w") as a:
        a.write('#usda 1.0\n(\n    defaultPrim = "Lamp"\n)\n\ndef Xform "Lamp"\n{\n')
        for k in range(PER_GROUP):
            a.write(light(f"L{k}", first + k, 4))
        a.write("}\n")


def group_open(g, meta=""):
    x, z = g % 100, g // 100
    return (
        f'    def Xform "G{g}"{meta}\n'
        "    {\n"
        f"        double3 xformOp:translate = ({x * 2}, 0, {z * 2})\n"
        '        uniform token[] xformOpOrder = ["xformOp:translate"]\n'
    )


def main():
    global PER_GROUP
    argv = sys.argv[1:]
    if "--per-group" in argv:
        k = argv.index("--per-group")
        PER_GROUP = int(argv[k + 1])
        del argv[k : k + 2]
    args = [a for a in argv if not a.startswith("--")]
    instanced = "--instanced" in argv
    own_layers = "--own-layers" in argv
    if instanced and own_layers:
        sys.exit(__doc__)
    if len(args) != 2:
        sys.exit(__doc__)
    n, out = int(args[0]), args[1]
    header = '#usda 1.0\n(\n    defaultPrim = "World"\n    metersPerUnit = 1\n    upAxis = "Y"\n)\n\n'
    with open(out, "w") as f:
        f.write(header)
        f.write('def Xform "World"\n{\n')
        if instanced or own_layers:
            if n % PER_GROUP:
                sys.exit(f"N must be a multiple of {PER_GROUP}")
            stem = os.path.splitext(out)[0]
            if instanced:
                lamp_layer(stem + "_asset.usda", 0)
            for g in range(n // PER_GROUP):
                if own_layers:
                    lamp_layer(f"{stem}_G{g}.usda", g * PER_GROUP)
                    ref = os.path.basename(f"{stem}_G{g}.usda")
                    meta = f" (\n        references = @./{ref}@\n    )"
                else:
                    ref = os.path.basename(stem + "_asset.usda")
                    meta = f" (\n        instanceable = true\n        references = @./{ref}@\n    )"
                f.write(group_open(g, meta) + "    }\n")
        else:
            for g in range((n + PER_GROUP - 1) // PER_GROUP):
                f.write(group_open(g))
                for k in range(min(PER_GROUP, n - g * PER_GROUP)):
                    f.write(light(f"L{k}", g * PER_GROUP + k, 8))
                f.write("    }\n")
        f.write("}\n")


if __name__ == "__main__":
    main()
